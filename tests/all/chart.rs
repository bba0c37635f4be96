//! Each pipeline charts its own outcome on the designer's map
//! (`pipelines::chart`, issue 38): what the map draws is read through the
//! outcome's face, and says what the pipeline computed.

use skyform::mission::{self, BUILTIN, Mission};
use skyform::outcome::{self, Outcome};
use skyform::pipelines::chart::{Chart, ChartView, Ink};
use skyform::pipelines::theta_pso::PlanOptions;
use skyform::pipelines::{CancelToken, Kind, Silent};

fn shipped(name: &str) -> Mission {
    let b = BUILTIN
        .iter()
        .find(|b| b.file_name == name)
        .unwrap_or_else(|| panic!("no bundled {name}"));
    mission::parse_str(b.text, b.file_name)
        .unwrap_or_else(|e| panic!("{name}: {e:?}"))
        .mission
}

fn run(kind: Kind, m: &Mission) -> Outcome {
    outcome::run(
        kind,
        m,
        m.seed,
        PlanOptions::default(),
        &mut Silent,
        &CancelToken::new(),
    )
    .unwrap_or_else(|e| panic!("{kind:?}: {e}"))
}

/// Everything charted, in order.
#[derive(Default)]
struct Drawn {
    lines: Vec<(Vec<[f64; 2]>, Ink)>,
    rings: Vec<([f64; 2], f64, Ink)>,
    marks: Vec<([f64; 2], String, Ink)>,
    layers: usize,
}

impl Chart for Drawn {
    fn line(&mut self, points: Vec<[f64; 2]>, ink: Ink) {
        self.lines.push((points, ink));
    }
    fn ring(&mut self, centre: [f64; 2], radius: f64, ink: Ink) {
        self.rings.push((centre, radius, ink));
    }
    fn mark(&mut self, at: [f64; 2], text: String, ink: Ink) {
        self.marks.push((at, text, ink));
    }
    fn layer(&mut self) {
        self.layers += 1;
    }
}

fn view(m: &Mission, stale: bool, at: Option<f64>) -> ChartView<'_> {
    ChartView {
        mission: m,
        stale,
        live: false,
        at,
    }
}

fn chart(o: &Outcome, v: &ChartView) -> Drawn {
    let mut drawn = Drawn::default();
    o.face().chart(v, &mut drawn);
    drawn
}

/// θ-PSO: a line per UAV in its colour, the centroid's path, and over them
/// the reconfiguration zones [t1, t4] and the inspection passes (eq. 8);
/// once the mission is edited, the tracks fade and the zones go.
#[test]
fn theta_pso_charts_its_tracks_zones_and_passes_and_fades_when_stale() {
    let m = shipped("bridge-inspection.toml");
    let out = run(Kind::ThetaPso, &m);
    let o = out.theta_pso().expect("θ-PSO outcome");
    assert!(!o.passes.is_empty(), "the bridge inspects its piers");
    let uavs = m.formation.slots.len();

    let fresh = chart(&out, &view(&m, false, None));
    let count = |d: &Drawn, ink: Ink| d.lines.iter().filter(|(_, i)| *i == ink).count();
    for k in 0..uavs {
        assert_eq!(count(&fresh, Ink::Vehicle(k)), 1, "UAV {}", k + 1);
    }
    assert_eq!(count(&fresh, Ink::Plain), 1, "the centroid's path");
    assert_eq!(count(&fresh, Ink::Zone), o.reconfigurations.len());
    assert_eq!(count(&fresh, Ink::Pass), o.passes.len());
    assert_eq!(fresh.layers, 1, "zones and passes over the tracks");
    let (centroid, _) = fresh.lines.iter().find(|(_, i)| *i == Ink::Plain).unwrap();
    let expected: Vec<[f64; 2]> = o.centroid_path.iter().map(|p| [p.x, p.y]).collect();
    assert_eq!(centroid, &expected);
    // A pass is charted where the centroid flies during it.
    let (pass, _) = fresh.lines.iter().find(|(_, i)| *i == Ink::Pass).unwrap();
    assert!(pass.len() > 1, "a pass spans samples");

    let stale = chart(&out, &view(&m, true, None));
    assert_eq!(count(&stale, Ink::Faded), uavs);
    assert_eq!(count(&stale, Ink::Grey), 1);
    assert_eq!(count(&stale, Ink::Zone) + count(&stale, Ink::Pass), 0);

    // The side view unrolls the flown path: every altitude line lies
    // within its length, at the UAVs' altitudes.
    let path = out.face().flown_path().expect("θ-PSO has a path");
    assert_eq!(path, o.flown_path.as_slice());
    let mut side = Drawn::default();
    out.face().chart_side(&view(&m, false, None), &mut side);
    assert_eq!(side.lines.len(), uavs);
    for (points, _) in &side.lines {
        for [s, z] in points {
            assert!(*s >= -1e-9 && *s <= o.path_length + 1e-6, "s = {s}");
            assert!(
                *z >= m.bounds.z[0] - 1.0 && *z <= m.bounds.z[1] + 1.0,
                "z = {z}"
            );
        }
    }
    // The designer turns the slots at the start along the flown path's
    // first step, which heads where the plan's first leg does.
    let start = o.centroid_path[0].xy();
    let first = out
        .face()
        .flown_path()
        .and_then(|p| p.iter().find(|p| (p.xy() - start).norm() > 1e-6))
        .map(|p| p.xy() - start)
        .expect("a flown path leaves the start");
    let leg = o.centroid_path[1].xy() - start;
    let turn = first.y.atan2(first.x) - leg.y.atan2(leg.x);
    assert!(
        turn.sin().abs() < 1e-6,
        "the first step turns {turn} rad off the first leg"
    );
    assert!(!out.kind().words().dwarfs_the_site);
}

/// The fleet at the replay's instant: each agent's trail ends at or before
/// it, the agent marked where its last sample is, its detection range
/// around it; at the end of the flight, the whole trail.
#[test]
fn the_fleet_charts_each_agent_at_the_replay_instant() {
    let m = shipped("fleet-triangle.toml");
    let out = run(Kind::Fleet, &m);
    let o = out.fleet().expect("fleet outcome");
    let half = o.duration / 2.0;
    let at_half = chart(&out, &view(&m, false, Some(half)));
    assert_eq!(at_half.lines.len(), o.agents.len());
    for (a, (trail, ink)) in o.agents.iter().zip(&at_half.lines) {
        assert_eq!(*ink, Ink::Vehicle(a.index));
        let upto = a.samples.iter().filter(|s| s.t <= half).count();
        assert_eq!(trail.len(), upto, "agent {}", a.index + 1);
        assert!(upto < a.samples.len(), "half way is not the end");
        let last = &a.samples[upto - 1];
        let mark = at_half
            .marks
            .iter()
            .find(|(_, text, _)| *text == format!("●{}", a.index + 1))
            .expect("the agent is marked");
        assert_eq!(mark.0, [last.position.x, last.position.y]);
    }
    assert_eq!(at_half.rings.len(), o.agents.len());
    assert!(
        at_half
            .rings
            .iter()
            .all(|(_, r, ink)| *r == m.fleet.detection_range && *ink == Ink::Faded)
    );
    let at_end = chart(&out, &view(&m, true, None));
    for (a, (trail, ink)) in o.agents.iter().zip(&at_end.lines) {
        assert_eq!(trail.len(), a.samples.len());
        assert_eq!(*ink, Ink::Grey, "a stale fleet is grey");
    }
}

/// FLATLO: each aircraft's reference (faded) under its flight, numbered
/// where it started and marked where it ended; at kilometre scale it
/// dwarfs the site, so the map leaves the site's labels off.
#[test]
fn flatlo_charts_references_under_flights_at_kilometre_scale() {
    let m = shipped("flatlo-squadron.toml");
    let out = run(Kind::Flatlo, &m);
    let o = out.flatlo().expect("FLATLO outcome");
    let drawn = chart(&out, &view(&m, false, None));
    let n = o.aircraft.len();
    assert_eq!(drawn.lines.len(), 2 * n);
    assert!(drawn.lines[..n].iter().all(|(_, ink)| *ink == Ink::Faded));
    for (a, (flown, ink)) in o.aircraft.iter().zip(&drawn.lines[n..]) {
        assert_eq!(*ink, Ink::Vehicle(a.index));
        assert_eq!(flown.len(), a.flown.len());
    }
    assert_eq!(drawn.marks.len(), 2 * n);
    assert!(out.kind().words().dwarfs_the_site);
    assert!(out.face().flown_path().is_none(), "no path to unroll");
}

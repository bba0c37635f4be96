//! Issue 51: a passage is found wherever it falls, decided on the
//! obstacles' own geometry, not on the route grid's cells; a refusal names
//! the passage that is too narrow and by how much, and writes it as JSON.

use nalgebra::Point2;
use skyform::mission::{self, Mission, Obstacle};
use skyform::pipelines::theta_pso::{PlanOptions, plan};
use skyform::pipelines::{CancelToken, PipelineError, Silent};

use crate::common::skyform;

/// A row of nine bays (footprints 8 m deep along the route, 2.6 m wide,
/// their bounding circles 4.2 m) across a site `length` metres long,
/// 0.5 m apart (no UAV passes) but for one `aisle` between bays 1.4 and
/// 1.5, the row shifted `offset` metres across the route; the end bays run
/// past the bounds, so the aisle is the only way. The triangle of r_Q 0.33.
pub(crate) fn bays(aisle: f64, offset: f64, length: f64) -> Mission {
    let text = format!(
        "name = \"bays\"\nseed = 1\n[bounds]\nx = [0.0, {length}]\ny = [-30.0, 30.0]\n\
         z = [3.0, 12.0]\n[route]\nstart = [5.0, 0.0, 8.0]\ngoal = [{}, 0.0, 8.0]\n\
         [formation]\nuav_radius = 0.33\n",
        length - 5.0
    );
    let mut m = mission::parse_str(&text, "bays.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    let (x0, x1) = (length / 2.0 - 4.0, length / 2.0 + 4.0);
    let mut rows = vec![(-45.0, -14.0 + offset)];
    let mut y = -14.0 + offset + 0.5;
    for k in 2..=8 {
        rows.push((y, y + 2.6));
        y += 2.6 + if k == 4 { aisle } else { 0.5 };
    }
    rows.push((y, 45.0));
    for (k, (y0, y1)) in rows.into_iter().enumerate() {
        let mut o = Obstacle::standing(format!("bay 1.{}", k + 1), Point2::origin(), 0.0, 30.0);
        o.footprint = vec![
            Point2::new(x0, y0),
            Point2::new(x1, y0),
            Point2::new(x1, y1),
            Point2::new(x0, y1),
        ];
        o.overfly = false;
        o.settle();
        m.obstacles.push(o);
    }
    m
}

fn feasible(m: &Mission) -> Result<bool, String> {
    plan(
        m,
        1,
        PlanOptions::default(),
        &mut Silent,
        &CancelToken::new(),
    )
    .map(|o| o.feasible())
    .map_err(|e| e.to_string())
}

/// Issue 51: the bays' aisle, 1.565 m (2 r_Q + 0.905 m), is found at each
/// of 13 offsets 2 cm apart, on a site 100 m long and on one of 1 km (the
/// route grid 2.5 m there; beb5696 refused all 13: its IWP was unusable,
/// the hold measured from the bays' bounding circles, which reach across
/// the aisle, so only the grid could find it).
#[test]
fn the_bays_aisle_is_found_at_every_offset_on_any_site_size() {
    for length in [100.0, 1000.0] {
        let found: Vec<Result<bool, String>> = (0..13)
            .map(|k| feasible(&bays(1.565, 0.02 * k as f64, length)))
            .collect();
        assert!(
            found.iter().all(|f| f == &Ok(true)),
            "{length} m: {found:?}"
        );
    }
}

/// Issue 51: a row whose only aisle is 5 cm narrower than one UAV needs is
/// refused naming that aisle and the 5 cm; `--json` writes the refusal
/// (the reason and the obstacles that close the way).
#[test]
fn an_aisle_five_cm_too_narrow_is_refused_naming_it_and_the_json_says_so() {
    let need = 2.0 * (0.33 + 0.1);
    let m = bays(need - 0.05, 0.0, 100.0);
    match plan(
        &m,
        1,
        PlanOptions::default(),
        &mut Silent,
        &CancelToken::new(),
    ) {
        Err(PipelineError::NoRoute(no)) => {
            assert!(
                no.reason
                    .contains("'bay 1.4' | 'bay 1.5', is 0.81 m: 0.05 m too narrow for one UAV"),
                "{}",
                no.reason
            );
            assert!(
                no.obstacles.contains(&"bay 1.4".to_owned()),
                "{:?}",
                no.obstacles
            );
        }
        other => panic!("{:?}", other.map(|o| o.feasible())),
    }
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let file = dir.path().join("bays.toml");
    let json = dir.path().join("no-plan.json");
    std::fs::write(
        &file,
        mission::to_toml_string(&m).unwrap_or_else(|e| panic!("{e}")),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let out = skyform(&[
        "run",
        "theta-pso",
        &file.display().to_string(),
        "--json",
        &json.display().to_string(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let text = std::fs::read_to_string(&json).unwrap_or_else(|e| panic!("{e}"));
    let v: serde_json::Value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(v["result"], "no plan");
    assert!(
        v["reason"]
            .as_str()
            .is_some_and(|r| r.contains("0.05 m too narrow")),
        "{v}"
    );
    assert!(
        v["obstacles"]
            .as_array()
            .is_some_and(|o| o.iter().any(|n| n == "bay 1.5")),
        "{v}"
    );
    // The blocking passages, widest first, with their ends to draw: the
    // aisle, 0.81 m of the 0.86 m one UAV needs, between the two bays'
    // facing edges (bay 1.4 from y = -13.5 + 2 × 3.1, 2.6 m wide; bay 1.5
    // 0.81 m on).
    let widest = &v["passages"][0];
    assert_eq!(widest["between"], serde_json::json!(["bay 1.4", "bay 1.5"]));
    assert!(
        (widest["width"].as_f64().unwrap_or(0.0) - 0.81).abs() < 1e-9,
        "{v}"
    );
    assert!(
        (widest["needs"].as_f64().unwrap_or(0.0) - 0.86).abs() < 1e-9,
        "{v}"
    );
    let ends = &widest["ends"];
    let y = |k: usize| ends[k][1].as_f64().unwrap_or(f64::NAN);
    assert!((y(0) - (-13.5 + 2.0 * 3.1 + 2.6)).abs() < 1e-9, "{v}");
    assert!((y(1) - y(0) - 0.81).abs() < 1e-9, "{v}");
    // The route that was tried, to draw beside them: from the start as far
    // as the formation reached, to its point nearest the goal; everywhere
    // clear of the bays by more than r_Q.
    let route: Vec<Point2<f64>> = v["route"]
        .as_array()
        .map(|r| {
            r.iter()
                .map(|p| {
                    Point2::new(
                        p[0].as_f64().unwrap_or(f64::NAN),
                        p[1].as_f64().unwrap_or(f64::NAN),
                    )
                })
                .collect()
        })
        .unwrap_or_default();
    assert!(route.len() >= 2, "{v}");
    let (start, goal) = (m.route.start.xy(), m.route.goal.xy());
    assert!((route[0] - start).norm() < 0.5, "begins at the start: {v}");
    let last = route[route.len() - 1];
    assert!(
        (last - goal).norm() < (start - goal).norm() - 1.0,
        "it got on towards the goal: {last} {v}"
    );
    let r_q = m.formation.least_clearance();
    for p in &route {
        for o in &m.obstacles {
            let d = o.outline().signed_distance(p);
            assert!(d > r_q, "{p} is {d:.2} m from '{}': {v}", o.name);
        }
    }
}

/// Issue 51: `check` on a row of footprints with 2.5 m aisles warns of no
/// unusable IWP (it warned of every aisle: its test measured from the
/// bays' bounding circles).
#[test]
fn check_finds_no_unusable_iwp_between_footprints_with_room() {
    let mut m = bays(2.5, 0.0, 100.0);
    // Every aisle 2.5 m.
    let mut y = -14.0 + 2.5;
    for k in 1..8 {
        let o = &mut m.obstacles[k];
        let (x0, x1) = (o.footprint[0].x, o.footprint[1].x);
        o.footprint = vec![
            Point2::new(x0, y),
            Point2::new(x1, y),
            Point2::new(x1, y + 2.6),
            Point2::new(x0, y + 2.6),
        ];
        o.settle();
        y += 2.6 + 2.5;
    }
    let report = skyform::outcome::diagnose::check_text(
        &mission::to_toml_string(&m).unwrap_or_else(|e| panic!("{e}")),
        Some("bays.toml"),
    )
    .report;
    let text = report.to_string();
    assert!(!text.contains("unusable"), "{text}");
}

/// What stands either side of an aisle in [`row`].
#[derive(Debug, Clone, Copy, PartialEq)]
enum Side {
    /// A post: a cylinder 0.8 m across.
    Post,
    /// A bay: a footprint 2.6 m along the row, 8 m deep.
    Bay,
}

/// One mission of the sweep: the dimensions a passage may vary in.
#[derive(Debug, Clone, Copy)]
struct Sweep {
    sides: [Side; 2],
    /// How much wider than the column needs (2 (r_Q + margins)), metres,
    /// or, `wide`, than the whole formation needs (2 (r_F + r_Q + margins)):
    /// no reconfiguration, no IWP, only the route's own search.
    excess: f64,
    wide: bool,
    /// The aisle against the north bound (the east side of the row gone).
    at_bound: bool,
    /// The aisle's place along the row, metres from the site's axis.
    offset: f64,
    /// The site: (length along the route, width across), metres.
    site: (f64, f64),
    /// The row's slant from square across the route, degrees.
    slant: f64,
    /// UAVs in the formation (a grid of rows of up to 4, 2.5 m apart).
    uavs: usize,
}

/// A row across the route with one aisle: next to the aisle an element of
/// each side's kind, one more of the same kind 0.5 m beyond it (too narrow
/// for any UAV), then a wall out past the bounds, so the aisle is the only
/// way. r_Q 0.33, margins 0.1 m: the column needs 0.86 m.
fn row(s: &Sweep) -> Mission {
    let (length, width) = s.site;
    let text = format!(
        "name = \"row\"\nseed = 1\n[bounds]\nx = [0.0, {length}]\ny = [{}, {}]\n\
         z = [3.0, 12.0]\n[route]\nstart = [5.0, 0.0, 8.0]\ngoal = [{}, 0.0, 8.0]\n\
         [formation]\nuav_radius = 0.33\n",
        -width / 2.0,
        width / 2.0,
        length - 5.0
    );
    let mut m = mission::parse_str(&text, "row.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    let columns = s.uavs.min(4);
    m.formation.slots = (0..s.uavs)
        .map(|k| {
            let (r, c) = ((k / columns) as f64, (k % columns) as f64);
            nalgebra::Vector3::new(-2.5 * r, 2.5 * (c - (columns as f64 - 1.0) / 2.0), 0.0)
        })
        .collect();
    let centroid = m.formation.slots.iter().sum::<nalgebra::Vector3<f64>>() / s.uavs as f64;
    for o in &mut m.formation.slots {
        *o -= centroid;
    }
    let slant = s.slant.to_radians();
    let along = nalgebra::Vector2::new(-slant.sin(), slant.cos());
    let across = nalgebra::Vector2::new(slant.cos(), slant.sin());
    let middle = Point2::new(length / 2.0, 0.0);
    let aisle = if s.wide {
        2.0 * (m.formation.radius() + m.formation.least_clearance()) + s.excess
    } else {
        2.0 * m.formation.least_clearance() + s.excess
    };
    // Against the bound: the aisle's east edge on it.
    let offset = if s.at_bound {
        width / 2.0 - aisle / 2.0
    } else {
        s.offset
    };
    let reach = width.max(length) * 2.0;
    // A footprint along the row from `a` to `b`, `half` deep either side.
    let strip = |name: String, a: f64, b: f64, half: f64| {
        let mut o = Obstacle::standing(name, Point2::origin(), 0.0, 30.0);
        o.footprint = vec![
            middle + along * a - across * half,
            middle + along * b - across * half,
            middle + along * b + across * half,
            middle + along * a + across * half,
        ];
        o
    };
    let mut pieces = Vec::new();
    for (k, sign) in [-1.0f64, 1.0].into_iter().enumerate() {
        if s.at_bound && k == 1 {
            break;
        }
        // `edge`: where the next piece starts, along the row from the aisle.
        let mut edge = offset + sign * aisle / 2.0;
        for n in 0..2 {
            let name = format!("{} {}", ["west", "east"][k], n + 1);
            match s.sides[k] {
                Side::Post => {
                    let c = middle + along * (edge + sign * 0.4);
                    pieces.push(Obstacle::standing(name, c, 0.4, 30.0));
                    edge += sign * (0.8 + 0.5);
                }
                Side::Bay => {
                    pieces.push(strip(name, edge, edge + sign * 2.6, 4.0));
                    edge += sign * (2.6 + 0.5);
                }
            }
        }
        pieces.push(strip(
            format!("{} wall", ["west", "east"][k]),
            edge,
            sign * reach,
            0.5,
        ));
    }
    for mut o in pieces {
        o.overfly = false;
        o.settle();
        m.obstacles.push(o);
    }
    m
}

/// The sweep's missions: every dimension drawn from its range by `index`.
fn sweep(index: u64) -> Sweep {
    use rand::{RngExt, SeedableRng};
    let mut rng =
        rand::rngs::ChaCha8Rng::seed_from_u64(0x0a15_1e51 ^ index.wrapping_mul(0x9e37_79b9));
    let kinds = [Side::Post, Side::Bay];
    let sites = [(100.0, 60.0), (420.0, 60.0), (1000.0, 1000.0)];
    let site = sites[rng.random_range(0..sites.len())];
    let slants = [0.0, 10.0, 30.0, 45.0];
    let slant = slants[rng.random_range(0..if site.1 > 100.0 { 3 } else { 4 })];
    let wide = rng.random_bool(0.3);
    let at_bound = rng.random_bool(0.15);
    Sweep {
        sides: [kinds[rng.random_range(0..2)], kinds[rng.random_range(0..2)]],
        excess: if wide {
            [0.05, 0.5, 2.0][rng.random_range(0..3)]
        } else {
            [0.05, 0.15, 0.3, 0.6][rng.random_range(0..4)]
        },
        wide,
        at_bound,
        slant: if at_bound { 0.0 } else { slant },
        offset: rng.random_range(-10.0..10.0),
        site,
        uavs: [3, 5, 9, 12][rng.random_range(0..4)],
    }
}

/// Issue 51: the first 24 missions of the sweep (posts and bays either
/// side, aisles from 5 cm over the column's need to 2 m over the whole
/// formation's, slants to 45°, aisles against the bounds, sites of 100 m,
/// 420 m and 1 km × 1 km, 3-12 UAVs) all plan FEASIBLE, and the voxel oracle
/// admits every one it can resolve (before the exact gaps and landings,
/// every 1 km² site but two was refused and every aisle against the bounds
/// failed).
#[test]
fn every_passage_of_the_sweep_is_found() {
    let mut admitted = 0;
    for i in 0..24 {
        let s = sweep(i);
        let m = row(&s);
        assert_eq!(feasible(&m), Ok(true), "sweep {i}: {s:?}");
        let c = m.formation.least_clearance() + 0.02;
        let grid = crate::common::oracle::Grid {
            cell: 0.05,
            layer: 100.0,
        };
        if s.excess >= 0.15 && s.site.1 < 100.0 {
            assert!(
                crate::common::oracle::passage_exists(&m, c, &grid),
                "sweep {i}: the oracle finds no way: {s:?}"
            );
            admitted += 1;
        }
    }
    assert!(admitted >= 8, "{admitted}");
}

/// The oracle itself: it finds the way through an aisle with room and none
/// through one 2 cm narrower than the clearance it keeps.
#[test]
fn the_oracle_tells_an_open_aisle_from_a_closed_one() {
    let grid = crate::common::oracle::Grid {
        cell: 0.05,
        layer: 100.0,
    };
    let base = Sweep {
        sides: [Side::Post, Side::Bay],
        excess: 0.3,
        wide: false,
        at_bound: false,
        offset: 1.3,
        site: (100.0, 60.0),
        slant: 10.0,
        uavs: 3,
    };
    let m = row(&base);
    let c = m.formation.least_clearance();
    assert!(crate::common::oracle::passage_exists(&m, c + 0.1, &grid));
    assert!(!crate::common::oracle::passage_exists(&m, c + 0.17, &grid));
}

/// Measures the sweep (`SKYFORM_SWEEP=N` missions, one seed each): the
/// oracle's verdict, the planner's and its time, as rates per dimension.
#[test]
#[ignore = "a measurement: SKYFORM_SWEEP=N cargo test --test all passages::sweep -- --ignored --nocapture"]
fn sweep_rates_per_dimension() {
    let n: u64 = std::env::var("SKYFORM_SWEEP")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(40);
    let mut rows = Vec::new();
    for i in 0..n {
        let s = sweep(i);
        let m = row(&s);
        if let Ok(dir) = std::env::var("SKYFORM_SWEEP_DUMP") {
            let text = mission::to_toml_string(&m).unwrap_or_else(|e| panic!("{e}"));
            std::fs::write(format!("{dir}/sweep-{i}.toml"), text).unwrap_or_else(|e| panic!("{e}"));
        }
        if std::env::var("SKYFORM_SWEEP_ONLY")
            .is_ok_and(|v| v.split(',').all(|k| k != i.to_string()))
        {
            continue;
        }
        let c = m.formation.least_clearance() + 0.02;
        let exists = crate::common::oracle::passage_exists(
            &m,
            c,
            &crate::common::oracle::Grid {
                cell: if s.site.1 > 100.0 { 0.1 } else { 0.05 },
                layer: 100.0,
            },
        );
        let t = std::time::Instant::now();
        let got = feasible(&m);
        let secs = t.elapsed().as_secs_f64();
        println!(
            "{i:4} {:?} excess {:.2}{} offset {:6.2}{} site {:?} slant {:2} uavs {:2}: oracle {exists} plan {got:?} {secs:.2} s",
            s.sides,
            s.excess,
            if s.wide { " (wide)" } else { "" },
            s.offset,
            if s.at_bound { " (bound)" } else { "" },
            s.site,
            s.slant,
            s.uavs
        );
        rows.push((s, exists, got == Ok(true), secs));
    }
    let found = rows.iter().filter(|r| r.1 && r.2).count();
    let exist = rows.iter().filter(|r| r.1).count();
    println!("found {found} of {exist} the oracle admits");
    let worst = rows.iter().map(|r| r.3).fold(0.0, f64::max);
    println!("worst time {worst:.2} s");
    // Rates per dimension: (name, value of a row).
    type Dimension = (&'static str, fn(&Sweep) -> String);
    let dimensions: [Dimension; 6] = [
        ("sides", |s| format!("{:?}", s.sides)),
        ("excess", |s| {
            format!("{}{}", s.excess, if s.wide { " wide" } else { "" })
        }),
        ("site", |s| format!("{:?}", s.site)),
        ("slant", |s| format!("{}", s.slant)),
        ("bound", |s| format!("{}", s.at_bound)),
        ("uavs", |s| format!("{}", s.uavs)),
    ];
    for (name, value) in dimensions {
        let mut keys: Vec<String> = rows.iter().map(|r| value(&r.0)).collect();
        keys.sort();
        keys.dedup();
        let cells: Vec<String> = keys
            .iter()
            .map(|k| {
                let of: Vec<_> = rows.iter().filter(|r| r.1 && &value(&r.0) == k).collect();
                let ok = of.iter().filter(|r| r.2).count();
                let mean = of.iter().map(|r| r.3).sum::<f64>() / of.len().max(1) as f64;
                format!("{k}: {ok}/{} ({mean:.2} s)", of.len())
            })
            .collect();
        println!("{name:7} {}", cells.join(", "));
    }
}

/// Issue 51: an obstacle margin that leaves the inspected pier's stand-off
/// band a few centimetres (the viaduct's [2, 5] m at 4.5 m: 5 cm above the
/// 4.95 m kept) is refused at once by `check` and `run`, naming the most
/// margin that leaves half a metre (it searched for 40 s and 500 MB and
/// ended INFEASIBLE).
#[test]
fn a_margin_that_leaves_no_band_to_inspect_in_is_refused_at_once() {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("missions/viaduct-inspection.toml"),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let mut m = mission::parse_str(&text, "viaduct-inspection.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    m.formation.obstacle_margin = 4.5;
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let file = dir.path().join("margin.toml");
    std::fs::write(
        &file,
        mission::to_toml_string(&m).unwrap_or_else(|e| panic!("{e}")),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let path = file.display().to_string();
    for args in [
        vec!["check", path.as_str()],
        vec!["run", "theta-pso", path.as_str()],
    ] {
        let out = skyform(&args);
        let said = String::from_utf8_lossy(&out.stderr).to_string()
            + &String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {said}");
        assert!(
            said.contains("'pier 5' cannot be inspected")
                && said.contains("leaves 0.05 m above the 4.95 m")
                && said.contains("lower formation.obstacle_margin to 4.05 m or less"),
            "{args:?}: {said}"
        );
    }
}

/// The Python of the OMPL oracle's venv (`tests/oracle_ompl/requirements.txt`).
fn ompl_python() -> Option<std::path::PathBuf> {
    crate::common::venv_python("SKYFORM_OMPL_VENV", "tests/oracle_ompl/requirements.txt")
}

/// OMPL's answers for `missions`, each written as TOML (the oracle reads
/// nothing else): (found, path length) per mission, in order.
fn ompl_answers(python: &std::path::Path, missions: &[(&Mission, f64)]) -> Vec<(bool, f64)> {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    missions
        .iter()
        .enumerate()
        .map(|(k, (m, seconds))| {
            let path = dir.path().join(format!("m{k}.toml"));
            let text = mission::to_toml_string(m).unwrap_or_else(|e| panic!("{e}"));
            std::fs::write(&path, text).unwrap_or_else(|e| panic!("{e}"));
            let out = std::process::Command::new(python)
                .arg(root.join("tests/oracle_ompl/oracle.py"))
                .args(["--clearance-add", "0.005", "--seed", "1"])
                .args(["--time", &seconds.to_string()])
                .arg(&path)
                .output()
                .unwrap_or_else(|e| panic!("{e}"));
            let stdout = String::from_utf8_lossy(&out.stdout);
            assert!(
                out.status.success(),
                "{stdout}\n{}",
                String::from_utf8_lossy(&out.stderr)
            );
            let row: serde_json::Value =
                serde_json::from_str(stdout.trim()).unwrap_or_else(|e| panic!("{e}: {stdout}"));
            let clearance = row["clearance"].as_f64().unwrap_or(f64::NAN);
            assert!(
                (clearance - (m.formation.least_clearance() + 0.005)).abs() < 1e-9,
                "the oracle read the clearance from the file: {row}"
            );
            (
                row["found"].as_bool().unwrap_or(false),
                row["length"].as_f64().unwrap_or(f64::NAN),
            )
        })
        .collect()
}

/// Issue 51's second oracle, OMPL (PRM with the bridge test on the exact
/// prisms, tests/oracle_ompl): it finds a way through two open aisles the
/// planner plans, a path no shorter than start to goal, and none through
/// the same aisle 2 cm narrower than the column needs. (Sampling proves
/// only what it finds: "none" here is 5 s without one through a closed
/// aisle, which no time would change.)
#[test]
fn ompl_finds_the_open_aisles_and_no_way_through_a_closed_one() {
    let Some(python) = ompl_python() else {
        return;
    };
    let open_sweep = Sweep {
        sides: [Side::Post, Side::Post],
        excess: 0.3,
        wide: false,
        at_bound: false,
        offset: -4.0,
        site: (100.0, 60.0),
        slant: 30.0,
        uavs: 5,
    };
    let open = row(&open_sweep);
    let bays = bays(1.565, 0.04, 100.0);
    let closed = row(&Sweep {
        excess: -0.02,
        ..open_sweep
    });
    let answers = ompl_answers(&python, &[(&open, 60.0), (&bays, 60.0), (&closed, 5.0)]);
    for (k, m) in [&open, &bays].into_iter().enumerate() {
        let (found, length) = answers[k];
        assert!(found, "OMPL found no way through open aisle {k}");
        let straight = (m.route.goal - m.route.start).norm();
        assert!(length >= straight - 1e-6, "{length} < {straight}");
        assert_eq!(feasible(m), Ok(true), "aisle {k}");
    }
    assert!(!answers[2].0, "OMPL went through the closed aisle");
}

/// Two rows of [`row`] in series, `apart` metres along the route, each
/// with its own aisle (the second's at `b`'s offset): the way bends
/// between them, past four obstacles of two rows. Same slant for both, so
/// their walls stay apart.
fn rows_in_series(a: &Sweep, b: &Sweep, apart: f64) -> Mission {
    let mut m = row(a);
    let second = row(b);
    let slant = a.slant.to_radians();
    let along_route = nalgebra::Vector2::new(slant.cos(), slant.sin()) * apart;
    for o in &mut m.obstacles {
        let c = o.center - along_route / 2.0;
        o.move_to(c);
        o.name = format!("first {}", o.name);
    }
    for mut o in second.obstacles {
        let c = o.center + along_route / 2.0;
        o.move_to(c);
        o.name = format!("second {}", o.name);
        m.obstacles.push(o);
    }
    m
}

/// The `i`th pair of rows of the series family and how far apart they
/// stand: the same slant, site and formation for both, neither against
/// the bounds.
fn series(i: u64) -> (Sweep, Sweep, f64) {
    let a = sweep(1000 + 2 * i);
    let mut b = sweep(1001 + 2 * i);
    b.slant = a.slant;
    b.site = a.site;
    b.uavs = a.uavs;
    b.at_bound = false;
    let a = Sweep {
        at_bound: false,
        ..a
    };
    (a, b, [8.0, 15.0, 30.0][(i % 3) as usize])
}

/// The `i`th case of the series, which the tests below were written for
/// as two rows 8 m apart on a 1 km site.
fn series_on_a_large_site(i: u64) -> Mission {
    let (a, b, apart) = series(i);
    assert_eq!((apart, a.site), (8.0, (1000.0, 1000.0)), "case {i} moved");
    rows_in_series(&a, &b, apart)
}

/// θ-PSO's plan of `m` (seed 1), which must be FEASIBLE: its summary
/// says why not.
fn planned_feasibly(m: &Mission) -> skyform::pipelines::theta_pso::ThetaPsoOutcome {
    let outcome = plan(
        m,
        1,
        PlanOptions::default(),
        &mut Silent,
        &CancelToken::new(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        outcome.feasible(),
        "{}",
        skyform::outcome::Outcome::ThetaPso(Box::new(outcome.clone())).summary()
    );
    outcome
}

/// Issue 51, series #6: two rows 8 m apart on a 1 km site, their walls
/// running 2 km on past it, the way bending from the first row's aisle
/// along the 3.5 m between the rows to the second's. A crossing was as
/// deep as the deeper of its two obstacles (a wall's 2 km, where a bay
/// flanks the gap for 8 m) and one pair of walls was nearest 1.5 km
/// outside the site: the route ran a 7,874 m corridor out of the bounds
/// and the run ended INFEASIBLE after 20 s. Now the plan is found, its
/// corridor near the start-goal line's length and inside the site.
#[test]
fn rows_in_series_plan_along_the_way_between_them_inside_the_site() {
    let m = series_on_a_large_site(6);
    let iwps = skyform::pipelines::theta_pso::find_iwps(&m);
    for iwp in iwps.iter().filter(|i| i.is_via()) {
        for p in iwp.straight_ends() {
            assert!(
                m.bounds.contains_xy(&p),
                "{:?}: its straight ends at {p:?}, outside the bounds",
                iwp.between
            );
        }
    }
    let outcome = planned_feasibly(&m);
    let line = (m.route.goal - m.route.start).norm();
    assert!(
        outcome.path_length < 1.1 * line,
        "path {:.1} m for a {line:.1} m line",
        outcome.path_length
    );
    for p in &outcome.centroid_path {
        assert!(
            m.bounds.contains_xy(&p.xy()),
            "the path leaves the site at {p:?}"
        );
    }
}

/// Issue 51, series #3: rows 8 m apart on a 1 km site, the way bending
/// from the first row's aisle along the 3.5 m between the rows into the
/// second's. At the whole site's 2.5 m cells the route found no corridor
/// ("a way bent between three or more that fits by less than about 2.50 m
/// may not be found"); the same rows on a 120 m site plan. The route now
/// looks again at finer cells in the window round the start, the goal and
/// the gaps, and plans it on the large site too.
#[test]
fn a_way_bent_between_two_rows_is_found_on_a_large_site() {
    let outcome = planned_feasibly(&series_on_a_large_site(3));
    let cell = outcome.corridor.coarse_cell.unwrap_or(0.0);
    assert!(cell < 1.0, "searched at {cell} m cells");
}

/// Issue 51: a refusal after the second look. On a 1 km site a low block
/// fills the only gap of a first wall (the formation could climb over it)
/// and a second wall is closed from bound to bound: the whole site's
/// search fails flat and over levels, and so does the window's. The
/// window's explanation of what closes the way reads its own grid (it once
/// read a grid of the whole site at the window's cells, which its search
/// had not covered); the refusal names the closed wall and says where it
/// looked again.
#[test]
fn a_closed_site_is_refused_after_the_second_look_over_levels() {
    let text = "name = \"closed\"\nseed = 1\n[bounds]\nx = [0.0, 1000.0]\ny = [-500.0, 500.0]\n\
                z = [3.0, 20.0]\n[route]\nstart = [5.0, 0.0, 8.0]\ngoal = [995.0, 0.0, 8.0]\n\
                [formation]\nuav_radius = 0.33\n";
    let mut m = mission::parse_str(text, "closed.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    for (name, [x0, x1, y0, y1], height, overfly) in [
        ("first south", [300.0, 301.0, -600.0, -1.0], 30.0, false),
        ("first north", [300.0, 301.0, 1.0, 600.0], 30.0, false),
        ("low block", [299.5, 301.5, -1.2, 1.2], 9.0, true),
        ("second wall", [600.0, 601.0, -600.0, 600.0], 30.0, false),
    ] {
        let mut o = Obstacle::standing(name.to_owned(), Point2::origin(), 0.0, height);
        o.footprint = vec![
            Point2::new(x0, y0),
            Point2::new(x1, y0),
            Point2::new(x1, y1),
            Point2::new(x0, y1),
        ];
        o.overfly = overfly;
        o.settle();
        m.obstacles.push(o);
    }
    match plan(
        &m,
        1,
        PlanOptions::default(),
        &mut Silent,
        &CancelToken::new(),
    ) {
        Err(PipelineError::NoRoute(no)) => {
            assert!(
                no.obstacles.contains(&"second wall".to_owned()),
                "{:?}: {}",
                no.obstacles,
                no.reason
            );
            assert!(
                no.reason.contains("searched again at finer cells"),
                "{}",
                no.reason
            );
        }
        other => panic!("{:?}", other.map(|o| o.feasible())),
    }
}

/// Measures two rows in series (`SKYFORM_SERIES=N` missions): both aisles
/// from 5 cm over the column's need, 8-30 m apart, offsets ±10 m, every
/// site size; the planner's verdict and time, and the voxel oracle's.
#[test]
#[ignore = "a measurement: SKYFORM_SERIES=N cargo test --release --test all passages::series -- --ignored --nocapture"]
fn series_rates() {
    let n: u64 = std::env::var("SKYFORM_SERIES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20);
    let (mut found, mut worst) = (0, 0.0f64);
    for i in 0..n {
        let (a, b, apart) = series(i);
        let m = rows_in_series(&a, &b, apart);
        if let Ok(dir) = std::env::var("SKYFORM_SWEEP_DUMP") {
            let text = mission::to_toml_string(&m).unwrap_or_else(|e| panic!("{e}"));
            std::fs::write(format!("{dir}/series-{i}.toml"), text)
                .unwrap_or_else(|e| panic!("{e}"));
        }
        let t = std::time::Instant::now();
        let got = feasible(&m);
        let secs = t.elapsed().as_secs_f64();
        worst = worst.max(secs);
        found += usize::from(got == Ok(true));
        println!(
            "{i:3} apart {apart:4} site {:?} slant {:2} uavs {:2} | {:?} {:.2}{} off {:6.2} | {:?} {:.2}{} off {:6.2}: {got:?} {secs:.2} s",
            a.site,
            a.slant,
            a.uavs,
            a.sides,
            a.excess,
            if a.wide { "w" } else { "" },
            a.offset,
            b.sides,
            b.excess,
            if b.wide { "w" } else { "" },
            b.offset
        );
    }
    println!("found {found} of {n}; worst {worst:.2} s");
}

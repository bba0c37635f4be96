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
fn bays(aisle: f64, offset: f64, length: f64) -> Mission {
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

//! The CI's share of the generated sites of `tests/sites` (issue 23): one to
//! three walls with one gap each, walls as close as 15 m, clutter, start and
//! goal near the bounds, 3 to 12 UAVs in nine shapes, half the sites
//! inspecting one or two towers; the paper's swarm. A plan exists on every
//! site by construction, so every run must be feasible.
//!
//! The full measurement (hundreds of runs, rates per dimension) is
//! `cargo run --release --no-default-features --example theta_pso_sites`.

use crate::sites;

use std::collections::BTreeSet;

use rayon::prelude::*;
use skyform::pipelines::theta_pso::{PlanOptions, plan};
use skyform::pipelines::{CancelToken, Silent};

/// Sites 400-423 (a range the planner was never tuned on), one seed each.
const SHARE: std::ops::Range<u64> = 400..424;

/// Sites 400-415 of the wide variant (more shapes, r_Q 0.3-0.7 m, sites
/// mirrored and transposed), one seed each.
const WIDE_SHARE: std::ops::Range<u64> = 400..416;

type Run = (sites::Site, Result<bool, String>, String);

/// A site planned with the paper's swarm on one core: feasible or refused
/// (why), and the first failure of its verification.
fn judged(mission: &skyform::mission::Mission, seed: u64) -> (Result<bool, String>, String) {
    match plan(
        mission,
        seed,
        PlanOptions { parallel: false },
        &mut Silent,
        &CancelToken::new(),
    ) {
        Ok(o) => (
            Ok(o.feasible()),
            o.verification.first_failure().unwrap_or_default(),
        ),
        Err(e) => (Err(e.to_string()), String::new()),
    }
}

/// Plans each site of `share` with the paper's swarm on one core.
fn plan_share(share: std::ops::Range<u64>, generate: fn(u64) -> sites::Site) -> Vec<Run> {
    share
        .into_par_iter()
        .map(|i| {
            let site = generate(i);
            let (feasible, why) = judged(&site.mission, i % 3);
            (site, feasible, why)
        })
        .collect()
}

/// Every run that was refused or infeasible, with why.
fn failures(runs: &[Run]) -> Vec<String> {
    runs.iter()
        .filter(|(_, feasible, _)| !matches!(feasible, Ok(true)))
        .map(|(site, feasible, why)| match feasible {
            Err(e) => format!("{}: refused: {e}", site.mission.name),
            _ => format!("{}: infeasible: {why}", site.mission.name),
        })
        .collect()
}

#[test]
fn every_site_of_the_share_is_planned_feasible() {
    let runs = plan_share(SHARE, sites::generated);

    // The share covers the family's dimensions, so a pass means something.
    let walls: BTreeSet<usize> = runs.iter().map(|r| r.0.walls).collect();
    let shapes: BTreeSet<&str> = runs.iter().map(|r| r.0.shape).collect();
    let inspected: BTreeSet<usize> = runs.iter().map(|r| r.0.inspected).collect();
    let largest = runs.iter().map(|r| r.0.uavs).max().unwrap_or(0);
    let close_walls = runs.iter().filter(|r| r.0.closest_walls < 22.0).count();
    assert_eq!(walls, BTreeSet::from([1, 2, 3]), "walls covered");
    assert!(shapes.len() >= 5, "shapes covered: {shapes:?}");
    assert_eq!(inspected, BTreeSet::from([0, 1, 2]), "inspections covered");
    assert!(largest >= 9, "largest formation {largest}");
    assert!(close_walls >= 2, "walls closer than 22 m: {close_walls}");

    let failures = failures(&runs);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_site_of_the_wide_share_is_planned_feasible() {
    let runs = plan_share(WIDE_SHARE, sites::generated_wide);
    let wide_shapes = runs
        .iter()
        .filter(|r| sites::WIDE_SHAPES.contains(&r.0.shape))
        .count();
    let radii: Vec<f64> = runs
        .iter()
        .map(|r| r.0.mission.formation.uav_radius)
        .collect();
    let northward = runs
        .iter()
        .filter(|r| {
            let route = r.0.mission.route.goal - r.0.mission.route.start;
            route.y.abs() > route.x.abs()
        })
        .count();
    assert!(wide_shapes >= 3, "shapes beyond the family: {wide_shapes}");
    assert!(
        radii.iter().any(|&r| r < 0.45) && radii.iter().any(|&r| r > 0.55),
        "r_Q varies: {radii:?}"
    );
    assert!(northward >= 3, "routes across the other axis: {northward}");
    let failures = failures(&runs);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A 3-D site's run: its name, its dimensions, feasible or refused (why),
/// the first failure.
type Run3d = (
    String,
    Vec<(&'static str, String)>,
    Result<bool, String>,
    String,
);

/// Sites 400-423 of the family in three dimensions (`sites::three_d`:
/// walls of posts and of segments with decoy pockets, rows of footprints
/// with aisles, decks, low fences, walls to fly over or climb, short
/// towers, trees near a bound), one seed each: every one planned feasible.
#[test]
fn every_site_of_the_three_dimensional_share_is_planned_feasible() {
    let runs: Vec<Run3d> = (400..424u64)
        .into_par_iter()
        .map(|i| {
            let site = sites::three_d::generated_3d(i);
            let (feasible, why) = judged(&site.mission, i % 3);
            (site.mission.name.clone(), site.dims, feasible, why)
        })
        .collect();
    // The share reaches the dimensions of the family.
    let barriers: BTreeSet<String> = runs
        .iter()
        .flat_map(|r| r.1.iter())
        .filter(|(d, _)| *d == "barrier")
        .map(|(_, v)| v.split(',').next().unwrap_or_default().to_owned())
        .collect();
    assert!(barriers.len() >= 4, "barrier kinds covered: {barriers:?}");
    let failures: Vec<String> = runs
        .iter()
        .filter(|r| !matches!(r.2, Ok(true)))
        .map(|r| match &r.2 {
            Err(e) => format!("{}: refused: {e}", r.0),
            _ => format!("{}: infeasible: {}", r.0, r.3),
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

//! θ-PSO over the generated sites of `tests/sites`: the feasible rate per
//! dimension (walls, shape, size, inspection, narrow gaps) and every failure
//! with its reason.
//!
//! ```text
//! cargo run --release --no-default-features --example theta_pso_sites -- 100 3
//! cargo run --release --no-default-features --example theta_pso_sites -- 100 3 200
//! ```
//! Arguments: sites, seeds per site (default 100 × 3), and the index of the
//! first site (default 0; a different range is a set the planner was not
//! tuned on). `--wide` measures the wide variant (`sites::generated_wide`:
//! more shapes, r_Q from 0.3 to 0.7 m, sites mirrored and transposed);
//! `--3d` the sites in three dimensions (`sites::three_d`: walls of posts
//! and segments, decoy pockets, rows of footprints, decks, low fences, walls
//! to fly over or climb, short towers and trees near a bound, 30 shapes);
//! `--3d-hard` their hard variant (more and closer barriers, narrower sites
//! and bands, uneven posts, more decoys, inspections and clutter).
//! `write DIR N [FIRST]` writes N sites of the chosen family as mission
//! files, to run them from the command line.

#[path = "../tests/all/sites/mod.rs"]
mod sites;

use std::collections::BTreeMap;
use std::time::Instant;

use rayon::prelude::*;
use skyform::pipelines::theta_pso::{PlanOptions, plan};
use skyform::pipelines::{CancelToken, Silent};

struct Run {
    site: u64,
    seed: u64,
    dims: Vec<(&'static str, String)>,
    feasible: bool,
    reason: String,
    seconds: f64,
}

/// One site and seed in detail: its IWPs, the seeding route, the result.
fn detail(m: &skyform::mission::Mission, seed: u64) {
    use skyform::pipelines::theta_pso::{Problem, seeding};
    println!(
        "{} — {} obstacles, bounds x {:?} y {:?}",
        m.name,
        m.obstacles.len(),
        m.bounds.x,
        m.bounds.y
    );
    println!("start {:?} goal {:?}", m.route.start, m.route.goal);
    let problem = match Problem::new(m) {
        Ok(p) => p,
        Err(e) => return println!("problem: {e:?}"),
    };
    for iwp in &problem.iwps {
        println!(
            "  IWP {} | {}: gap {:.2} {} hold {:.1} {}",
            iwp.between[0],
            iwp.between[1],
            iwp.gap,
            iwp.shape_name(),
            iwp.hold,
            iwp.unusable.as_deref().unwrap_or("")
        );
    }
    let mut problem = problem;
    for [a, z] in problem.builder.crossings() {
        println!(
            "  crossing ({:.2},{:.2}) -> ({:.2},{:.2})",
            a.x, a.y, z.x, z.y
        );
    }
    let t = Instant::now();
    let corridor = match skyform::pipelines::theta_pso::route::find(
        m,
        &problem.builder,
        &problem.iwps,
        problem.cost.margin(),
    ) {
        Ok(c) => c,
        Err(b) => {
            return println!(
                "  route: {} ({:.1} ms)",
                b.reason,
                t.elapsed().as_secs_f64() * 1e3
            );
        }
    };
    println!(
        "  route: {:.1} m, {} points, squeeze {} ({:.1} ms)",
        corridor.length,
        corridor.points.len(),
        corridor.squeeze.is_some(),
        t.elapsed().as_secs_f64() * 1e3
    );
    for (q, l) in corridor.points.iter().zip(&corridor.legs) {
        print!(" ({:.1},{:.1}) {l:?}", q.x, q.y);
    }
    println!();
    problem.follow(m, &corridor);
    let starts = seeding::particles(m, &problem, &corridor, seed);
    if let Some(p) = starts.first() {
        let path = problem.path(p);
        let t = problem.evaluate(p);
        println!(
            "  seed particle: {} points, J {:.2} J2 {:.5} J3 {:.4} JB {:.4}, zones {}",
            path.points.len(),
            t.total,
            t.obstacle,
            t.altitude,
            t.bounds,
            path.zones.len()
        );
        for q in &path.points {
            print!(" ({:.1},{:.1})", q.x, q.y);
        }
        println!();
    } else {
        println!("  no seeding route");
    }
    let t0 = Instant::now();
    let mut stages = |event: skyform::pipelines::Event<'_>| match event {
        skyform::pipelines::Event::Stage(s) => {
            println!("    {:>7.3} s  stage {s}", t0.elapsed().as_secs_f64())
        }
        skyform::pipelines::Event::Log(_, l)
            if !l.contains("unusable") && !l.starts_with("IWP") =>
        {
            println!("    {:>7.3} s  {l}", t0.elapsed().as_secs_f64())
        }
        _ => {}
    };
    match plan(
        m,
        seed,
        PlanOptions { parallel: false },
        &mut stages,
        &CancelToken::new(),
    ) {
        Ok(o) => {
            println!(
                "  result: feasible {} J {:.2} J2 {:.5} restarts {} zones {} source {:?} ({:.2} s)",
                o.feasible(),
                o.cost.total,
                o.cost.obstacle,
                o.restarts,
                o.reconfigurations.len(),
                o.source,
                t0.elapsed().as_secs_f64()
            );
            println!("  {}", o.verification.first_failure().unwrap_or_default());
            for r in &o.reconfigurations {
                println!(
                    "    reconfig {:?} {:?} {} t {:.1} {:.1} {:.1} {:.1}",
                    r.iwp,
                    r.between,
                    r.shape.name(),
                    r.t1,
                    r.t2,
                    r.t3,
                    r.t4
                );
            }
            for q in &o.centroid_path {
                print!(" ({:.1},{:.1},{:.1})", q.x, q.y, q.z);
            }
            println!();
        }
        Err(e) => println!("  refused: {e}"),
    }
}

/// Which way the route runs, start to goal, by its larger component.
fn heading(m: &skyform::mission::Mission) -> &'static str {
    let d = m.route.goal - m.route.start;
    match (d.x.abs() >= d.y.abs(), d.x >= 0.0, d.y >= 0.0) {
        (true, true, _) => "eastward",
        (true, false, _) => "westward",
        (false, _, true) => "northward",
        (false, _, false) => "southward",
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut raw: Vec<String> = std::env::args().skip(1).collect();
    let wide = raw.iter().any(|a| a == "--wide");
    let three_d = raw.iter().any(|a| a == "--3d");
    let hard = raw.iter().any(|a| a == "--3d-hard");
    raw.retain(|a| a != "--wide" && a != "--3d" && a != "--3d-hard");
    let generated = if wide {
        sites::generated_wide
    } else {
        sites::generated
    };
    // A site of the chosen family: its mission, the dimensions it is
    // reported by, and its mission file's text when it has one.
    let family = move |i: u64| -> (
        skyform::mission::Mission,
        Vec<(&'static str, String)>,
        Option<String>,
    ) {
        if three_d || hard {
            let site = if hard {
                sites::three_d::generated_3d_hard(i)
            } else {
                sites::three_d::generated_3d(i)
            };
            let mut dims = site.dims;
            dims.push(("route", heading(&site.mission).to_owned()));
            return (site.mission, dims, Some(site.toml));
        }
        let site = generated(i);
        let dims = vec![
            ("walls", site.walls.to_string()),
            ("narrow gaps", site.narrow.to_string()),
            ("shape", site.shape.to_owned()),
            ("UAVs", site.uavs.to_string()),
            ("inspected", site.inspected.to_string()),
            ("route", heading(&site.mission).to_owned()),
            (
                "closest walls",
                if site.closest_walls < 22.0 {
                    "< 22 m".to_owned()
                } else {
                    "≥ 22 m".to_owned()
                },
            ),
        ];
        (site.mission, dims, None)
    };
    if raw.first().map(String::as_str) == Some("detail") {
        let n = |i: usize| raw.get(i).and_then(|v| v.parse().ok()).unwrap_or(0);
        detail(&family(n(1)).0, n(2));
        return Ok(());
    }
    if raw.first().map(String::as_str) == Some("write") {
        let dir = std::path::PathBuf::from(raw.get(1).ok_or("write DIR N [FIRST]")?);
        let n = |i: usize, or: u64| raw.get(i).and_then(|v| v.parse().ok()).unwrap_or(or);
        std::fs::create_dir_all(&dir)?;
        for i in n(3, 0)..n(3, 0) + n(2, 10) {
            let (mission, _, text) = family(i);
            let text = match text {
                Some(t) => t,
                None => skyform::mission::to_toml_string(&mission)?,
            };
            std::fs::write(dir.join(format!("site-{i}.toml")), text)?;
        }
        return Ok(());
    }
    if raw.first().map(String::as_str) == Some("mission") {
        // A mission file in the same detail: `mission PATH SEED`.
        let path = raw.get(1).ok_or("mission PATH SEED")?;
        let seed = raw.get(2).and_then(|v| v.parse().ok()).unwrap_or(0);
        let loaded = skyform::mission::load(std::path::Path::new(path))?;
        detail(&loaded.mission, seed);
        return Ok(());
    }
    let args: Vec<u64> = raw.iter().map(|a| a.parse()).collect::<Result<_, _>>()?;
    let count = args.first().copied().unwrap_or(100);
    let seeds = args.get(1).copied().unwrap_or(3);
    let first = args.get(2).copied().unwrap_or(0);
    if seeds == 0 {
        // A census of the sites alone, no planning.
        let mut by: BTreeMap<String, usize> = BTreeMap::new();
        for i in first..first + count {
            for (dim, value) in family(i).1 {
                *by.entry(format!("{dim} {value}")).or_default() += 1;
            }
        }
        for (k, v) in by {
            println!("{k:<20} {v}");
        }
        return Ok(());
    }
    let jobs: Vec<(u64, u64)> = (first..first + count)
        .flat_map(|i| (0..seeds).map(move |s| (i, s)))
        .collect();
    let started = Instant::now();
    let runs: Vec<Run> = jobs
        .par_iter()
        .map(|&(i, seed)| {
            let (mission, dims, _) = family(i);
            let t = Instant::now();
            let outcome = plan(
                &mission,
                seed,
                PlanOptions { parallel: false },
                &mut Silent,
                &CancelToken::new(),
            );
            let seconds = t.elapsed().as_secs_f64();
            let (feasible, reason) = match outcome {
                Ok(o) => (
                    o.feasible(),
                    o.verification.first_failure().unwrap_or_default(),
                ),
                Err(e) => (false, format!("refused: {e}")),
            };
            Run {
                site: i,
                seed,
                dims,
                feasible,
                reason,
                seconds,
            }
        })
        .collect();
    let feasible = runs.iter().filter(|r| r.feasible).count();
    println!(
        "sites {first}..{}: {feasible} of {} runs feasible ({:.1} %), {:.0} s wall",
        first + count,
        runs.len(),
        100.0 * feasible as f64 / runs.len().max(1) as f64,
        started.elapsed().as_secs_f64()
    );
    let mut by: BTreeMap<(&str, String), (usize, usize)> = BTreeMap::new();
    for r in &runs {
        for (dim, value) in &r.dims {
            let e = by.entry((dim, value.clone())).or_default();
            e.1 += 1;
            if r.feasible {
                e.0 += 1;
            }
        }
    }
    let mut last = "";
    for ((dim, value), (ok, all)) in &by {
        if *dim != last {
            println!("  {dim}:");
            last = dim;
        }
        println!("    {value:<28} {ok:>4} / {all:<4}");
    }
    let slowest = runs.iter().map(|r| r.seconds).fold(0.0, f64::max);
    let mean = runs.iter().map(|r| r.seconds).sum::<f64>() / runs.len().max(1) as f64;
    println!("  time per run: mean {mean:.2} s, slowest {slowest:.2} s");
    let mut by_time: Vec<&Run> = runs.iter().collect();
    by_time.sort_by(|a, b| b.seconds.total_cmp(&a.seconds));
    for r in by_time.iter().take(5) {
        println!(
            "    slow: site {} seed {} {:.2} s",
            r.site, r.seed, r.seconds
        );
    }
    for r in runs.iter().filter(|r| !r.feasible) {
        let dims: Vec<String> = r.dims.iter().map(|(d, v)| format!("{d} {v}")).collect();
        println!(
            "  FAIL site {} seed {} ({}): {}",
            r.site,
            r.seed,
            dims.join(", "),
            r.reason
        );
    }
    Ok(())
}

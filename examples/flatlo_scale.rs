//! FLATLO at scale: how long and how much memory a large squadron takes.
//!
//! ```text
//! cargo run --release --no-default-features --example flatlo_scale -- 128
//! cargo run --release --no-default-features --example flatlo_scale -- 512 500 150
//! ```
//! Arguments: aircraft, then optionally Δ_d and the turn radius in metres
//! (default: the paper's, from `missions/flatlo-squadron.toml`). Run it under
//! `/usr/bin/time -v` for the peak memory (maximum resident set size).

use std::time::Instant;

use skyform::mission;
use skyform::pipelines::{CancelToken, Silent};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/missions/flatlo-squadron.toml");
    let mut m = mission::load(std::path::Path::new(path))?.mission;
    if let Some(n) = args.first() {
        m.flatlo.aircraft = n.parse()?;
    }
    if let Some(spacing) = args.get(1) {
        m.flatlo.spacing = spacing.parse()?;
    }
    if let Some(radius) = args.get(2) {
        m.flatlo.turn_radius = radius.parse()?;
    }
    let refused = skyform::pipelines::flatlo::budget(&m);
    if !refused.is_empty() {
        for d in refused {
            eprintln!("refused: {d}");
        }
        return Ok(());
    }
    let started = Instant::now();
    let out = skyform::pipelines::flatlo::plan(&m, m.seed, &mut Silent, &CancelToken::new())?;
    let kept: usize = out.aircraft.iter().map(|a| a.flown.len()).sum();
    println!(
        "{} aircraft, Δd {} m, r {} m: {:.0} s simulated in {:.2} s wall; stride {}, {} samples kept; closest {}; {}",
        m.flatlo.aircraft,
        m.flatlo.spacing,
        m.flatlo.turn_radius,
        out.duration,
        started.elapsed().as_secs_f64(),
        out.sample_stride,
        kept,
        out.closest.map_or("-".into(), |c| format!(
            "{}-{} at {:.0} m",
            c.a, c.b, c.min_distance
        )),
        if out.passed() { "PASS" } else { "FAIL" }
    );
    Ok(())
}

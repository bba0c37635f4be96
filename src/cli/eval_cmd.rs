//! `skyform eval`: the cost of given paths, the parity hook with the
//! reference implementations.

use std::path::{Path, PathBuf};

use super::{exit, load_reporting};
use crate::mission::{CostKind, Mission};
use crate::pipelines::theta_pso::spso;
use crate::pipelines::theta_pso::{CostModel, path::CentroidPath};

/// The arguments of `skyform eval` (its help is on `Command::Eval`).
#[derive(Debug, clap::Args)]
pub struct EvalArgs {
    /// Mission TOML file.
    pub mission: PathBuf,
    /// CSV file of paths: one per row, 3 n numbers (the n free nodes' x,
    /// then y, then z above the ground); `-` reads stdin. Blank lines and
    /// lines starting with `#` are skipped.
    #[arg(long, value_name = "FILE|-")]
    pub paths: PathBuf,
    /// Print J1 J2 J3 J4 after J on each line.
    #[arg(long)]
    pub terms: bool,
}

/// One path per row of `text`: 3 n numbers separated by commas or spaces.
pub fn parse_paths(text: &str, n: usize) -> Result<Vec<Vec<f64>>, String> {
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let values: Result<Vec<f64>, String> = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .map(|s| {
                s.parse::<f64>()
                    .map_err(|_| format!("line {}: '{s}' is not a number", i + 1))
            })
            .collect();
        let values = values?;
        if values.len() != 3 * n {
            return Err(format!(
                "line {}: {} numbers, expected 3 n = {} (x1..x{n}, y1..y{n}, z1..z{n})",
                i + 1,
                values.len(),
                3 * n
            ));
        }
        rows.push(values);
    }
    Ok(rows)
}

/// The costs of `rows` under the mission's cost: J and its terms.
/// The θ-PSO paper's cost sees the path start → nodes → goal (with the
/// ground added under terrain), without IWP crossings or passes.
pub fn evaluate(
    mission: &Mission,
    rows: &[Vec<f64>],
) -> Result<Vec<(f64, [f64; 4], bool)>, String> {
    match mission.theta_pso.cost {
        CostKind::Spso => {
            let model = spso::model(mission)?;
            Ok(rows
                .iter()
                .map(|r| {
                    let t = model.terms(r);
                    (
                        t.total,
                        [t.length, t.threat, t.altitude, t.smoothness],
                        t.off_map,
                    )
                })
                .collect())
        }
        CostKind::Paper => {
            let cost = CostModel::new(mission, &[]);
            let n = mission.theta_pso.waypoints;
            Ok(rows
                .iter()
                .map(|r| {
                    let mut points = vec![mission.route.start];
                    points.extend(
                        (0..n).map(|i| nalgebra::Point3::new(r[i], r[n + i], r[2 * n + i])),
                    );
                    points.push(mission.route.goal);
                    for p in &mut points {
                        p.z += mission.ground(p.x, p.y);
                    }
                    let t = cost.terms(&CentroidPath::bare(points));
                    (
                        t.total,
                        [t.length, t.obstacle, t.altitude, t.turning],
                        false,
                    )
                })
                .collect())
        }
    }
}

pub fn eval_command(args: &EvalArgs) -> u8 {
    let Some(mission) = load_reporting(&args.mission) else {
        return exit::ERROR;
    };
    let text = if args.paths == Path::new("-") {
        let mut s = String::new();
        if let Err(e) = std::io::Read::read_to_string(&mut std::io::stdin(), &mut s) {
            eprintln!("error: cannot read stdin: {e}");
            return exit::ERROR;
        }
        s
    } else {
        match std::fs::read_to_string(&args.paths) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("error: cannot read {}: {e}", args.paths.display());
                return exit::ERROR;
            }
        }
    };
    let rows = match parse_paths(&text, mission.theta_pso.waypoints) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {}: {e}", args.paths.display());
            return exit::ERROR;
        }
    };
    let costs = match evaluate(&mission, &rows) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return exit::ERROR;
        }
    };
    let mut out = String::new();
    for (i, (j, terms, off_map)) in costs.iter().enumerate() {
        if *off_map {
            eprintln!(
                "warning: path {}: a point's pixel is outside the terrain map (the reference \
                 code raises an index error); its cost is inf",
                i + 1
            );
        }
        out.push_str(&spso::g17(*j));
        if args.terms {
            for t in terms {
                out.push(' ');
                out.push_str(&spso::g17(*t));
            }
        }
        out.push('\n');
    }
    print!("{out}");
    exit::OK
}

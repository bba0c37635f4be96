//! Issue 52, item 4: a check split into shards merges into the report one
//! process gives, bit for bit, and a campaign's shards run on a real
//! distributed engine (a local Ray cluster) merge the same way.

use std::path::{Path, PathBuf};

use skyform::export::Planned;
use skyform::flight::shard::{self, Misjoin, Part, Shard};
use skyform::flight::{self, Options, Report, Setup};
use skyform::mission::{self, Mission};
use skyform::outcome;
use skyform::pipelines::theta_pso::PlanOptions;
use skyform::pipelines::{CancelToken, Kind, Silent};

fn bridge() -> Mission {
    mission::default_mission().mission
}

fn planned(m: &Mission) -> Planned {
    let o = outcome::run(
        Kind::ThetaPso,
        m,
        1,
        PlanOptions::default(),
        &mut Silent,
        &CancelToken::new(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    Planned::from_outcome(m, &o)
}

fn parts(setup: &Setup, m: &Mission, options: Options, count: usize) -> Vec<Part> {
    (0..count)
        .map(|index| {
            let part = shard::fly_shard(
                setup,
                mission::to_toml_string(m).unwrap_or_else(|e| panic!("{e}")),
                Kind::ThetaPso,
                options,
                Shard { index, count },
                &|_, _| {},
                &CancelToken::new(),
            )
            .unwrap_or_else(|e| panic!("{e}"));
            // Through the file format, as a part written elsewhere would be.
            let text = serde_json::to_string(&part).unwrap_or_else(|e| panic!("{e}"));
            serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}"))
        })
        .collect()
}

/// 4 shards of 120 flights, each written and read back as JSON, merged in
/// another order, give the report of one process to the byte.
#[test]
fn four_shards_merged_are_one_process_bit_for_bit() {
    let m = bridge();
    let planned = planned(&m);
    let setup = Setup::new(&m, &planned).unwrap_or_else(|e| panic!("{e}"));
    let options = Options {
        flights: 120,
        seed: 1,
        threads: None,
    };
    let one = flight::check(&setup, options, &|_, _| {}, &CancelToken::new())
        .unwrap_or_else(|e| panic!("{e}"));
    let mut parts = parts(&setup, &m, options, 4);
    assert_eq!(parts[1].flown.first().map(|f| f.flight), Some(30));
    parts.reverse();
    let (first, flown) = shard::merge(parts.clone()).unwrap_or_else(|e| panic!("{e}"));
    let merged = Report::new(&setup, options, &flown, &flight::as_written(&setup));
    let json = |r: &Report| serde_json::to_string_pretty(r).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(json(&merged), json(&one));
    assert_eq!(first.flights, 120);

    // A shard missing, a shard twice, a part of another check: refused.
    assert_eq!(
        shard::merge(parts[1..].to_vec())
            .map(|_| ())
            .map_err(|e| e.why),
        Err(Misjoin::Missing(90))
    );
    assert_eq!(
        shard::merge(parts[1..].to_vec())
            .err()
            .map(|e| e.to_string()),
        Some("flight 90 is in no part: a shard is missing".to_owned())
    );
    let mut twice = parts.clone();
    twice.push(parts[0].clone());
    assert_eq!(
        shard::merge(twice).map(|_| ()).map_err(|e| e.why),
        Err(Misjoin::Twice(90))
    );
    // A part that claims more flights than a check may fly sizes nothing.
    let mut huge = parts.clone();
    huge[0].flights = usize::MAX;
    assert_eq!(
        shard::merge(huge).map(|_| ()).map_err(|e| e.why),
        Err(Misjoin::TooMany(usize::MAX))
    );
    let mut other = parts.clone();
    other[2].seed = 2;
    assert_eq!(
        shard::merge(other).map(|_| ()).map_err(|e| e.why),
        Err(Misjoin::Mismatch {
            part: 3,
            what: "seed"
        })
    );
}

/// The Python of the campaign's venv (`tests/campaign/requirements.txt`, Ray).
fn campaign_python() -> Option<PathBuf> {
    crate::common::venv_python("SKYFORM_CAMPAIGN_VENV", "tests/campaign/requirements.txt")
}

fn file(path: &Path) -> std::fs::File {
    std::fs::File::create(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A campaign (the bridge × two weathers, 4 shards each) runs its shards
/// as tasks on a local single-node Ray cluster; each case's merged report
/// is the single process's, byte for byte (tests/campaign/ray_campaign.py).
#[test]
fn a_campaign_runs_its_shards_on_a_ray_cluster_and_merges_to_one_process() {
    let Some(python) = campaign_python() else {
        return;
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let mut child = std::process::Command::new(python)
        .arg(root.join("tests/campaign/ray_campaign.py"))
        .args(["--skyform", env!("CARGO_BIN_EXE_skyform")])
        .arg("--out")
        .arg(dir.path())
        .arg("--mission")
        .arg(root.join("missions/bridge-inspection.toml"))
        .args(["--flights", "100", "--shards", "4"])
        .args(["--rare-runs", "3", "--per-level", "20"])
        .env("RAY_USAGE_STATS_ENABLED", "0")
        .stdout(file(&dir.path().join("stdout")))
        .stderr(file(&dir.path().join("stderr")))
        .spawn()
        .unwrap_or_else(|e| panic!("{e}"));
    // Bounded: a cluster that does not come up ends the test, not CI.
    let started = std::time::Instant::now();
    while child.try_wait().ok().flatten().is_none() {
        if started.elapsed() > std::time::Duration::from_secs(600) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("the Ray campaign took over 600 s");
        }
        std::thread::sleep(std::time::Duration::from_millis(200));
    }
    let status = child.wait().unwrap_or_else(|e| panic!("{e}"));
    let read = |name: &str| std::fs::read_to_string(dir.path().join(name)).unwrap_or_default();
    let (stdout, stderr) = (read("stdout"), read("stderr"));
    assert_eq!(status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(stdout.contains("ray cluster: 1 node(s)"), "{stdout}");
    assert_eq!(
        stdout
            .matches("check, 4 shards on Ray merged == one process")
            .count(),
        2,
        "{stdout}"
    );
    assert_eq!(
        stdout
            .matches("rare, 3 shards on Ray merged == one process")
            .count(),
        2,
        "{stdout}"
    );
}

/// A rare-event estimate of 4 independent runs split into 3 shards (one
/// of them empty: shards may outnumber nothing but runs), each written and
/// read back as JSON, merged in another order: the report of one process
/// to the byte. Its runs are independent (run 0 is the single estimate of
/// the seed itself, the others differ), and a missing run is refused.
#[test]
fn a_rare_estimate_in_shards_of_runs_merges_to_one_process_bit_for_bit() {
    use skyform::flight::odds::{self, OddsReport};
    use skyform::flight::rare::{self, Limit, RareOptions};
    let mut m = bridge();
    m.flight.gnss_sigma_horizontal = 0.3;
    let planned = planned(&m);
    let setup = Setup::new(&m, &planned).unwrap_or_else(|e| panic!("{e}"));
    let options = RareOptions {
        per_level: 20,
        seed: 5,
        threads: None,
    };
    let cancel = CancelToken::new();
    let runs = |r: std::ops::Range<usize>| {
        odds::fly_runs(&setup, options, r, &|_, _, _, _| {}, &cancel)
            .unwrap_or_else(|e| panic!("{e}"))
    };
    let one = OddsReport::new(&m.name, 5, 20, runs(0..4));
    let single = rare::estimate(&setup, Limit::Separation, options, &|_, _| {}, &cancel)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(one.separation.runs[0].estimate, single.estimate);
    assert_ne!(one.separation.runs[1].levels, one.separation.runs[0].levels);
    let mean = one.separation.runs.iter().map(|e| e.estimate).sum::<f64>() / 4.0;
    assert!((one.separation.estimate - mean).abs() <= 1e-15 * mean.max(1.0));

    let toml = mission::to_toml_string(&m).unwrap_or_else(|e| panic!("{e}"));
    let mut parts: Vec<odds::Part> = (0..3)
        .map(|index| {
            let shard = Shard { index, count: 3 };
            let part = odds::Part {
                format: odds::PART_FORMAT.to_owned(),
                mission: toml.clone(),
                name: m.name.clone(),
                pipeline: Kind::ThetaPso,
                seed: 5,
                per_level: 20,
                runs: 4,
                shard,
                done: runs(shard.range(4)),
            };
            let text = serde_json::to_string(&part).unwrap_or_else(|e| panic!("{e}"));
            serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}"))
        })
        .collect();
    parts.reverse();
    let merged = odds::merge(parts.clone()).unwrap_or_else(|e| panic!("{e}"));
    let json = |r: &OddsReport| serde_json::to_string_pretty(r).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(json(&merged), json(&one));
    assert_eq!(
        odds::merge(parts[1..].to_vec())
            .map(|_| ())
            .map_err(|e| e.why),
        Err(Misjoin::Missing(2))
    );
    assert_eq!(
        odds::merge(parts[1..].to_vec())
            .err()
            .map(|e| e.to_string()),
        Some("run 2 is in no part: a shard is missing".to_owned())
    );
}

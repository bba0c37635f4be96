//! The distributed fleet over Zenoh (issue 26): agent processes of the real
//! binary on 127.0.0.1 (a free port per run, no scouting), every wait
//! bounded, and every process a test starts gone when it ends (checked).

#![cfg(all(feature = "zenoh", feature = "rerun"))]

use std::path::PathBuf;
use std::time::{Duration, Instant};

use skyform::distributed::{self, Options};
use skyform::mission::{self, Mission};
use skyform::pipelines::fleet::{self, FleetOutcome};
use skyform::pipelines::{CancelToken, Completion, Event, Observer, PipelineError, Silent};

fn skyform() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_skyform"))
}

/// The paper's triangle, flown for `seconds` (its first target).
fn triangle(seconds: f64) -> Mission {
    let mut m = match mission::load(std::path::Path::new("missions/fleet-triangle.toml")) {
        Ok(l) => l.mission,
        Err(e) => panic!("{e}"),
    };
    m.fleet.duration = Some(seconds);
    m.fleet.targets.retain(|t| t.time < seconds);
    m
}

fn options(processes: usize) -> Options {
    Options {
        processes,
        realtime: false,
        program: skyform(),
        timeout: Duration::from_secs(20),
    }
}

/// Keeps the agent processes' pids from the coordinator's log, and kills
/// one (-9) when the run is `kill_at` of the way through.
#[derive(Default)]
struct Watcher {
    pids: Vec<u32>,
    kill_at: Option<(f64, usize)>,
    killed: Option<u32>,
}

impl Observer for Watcher {
    fn on_event(&mut self, event: Event<'_>) {
        match event {
            Event::Log(_, text) => {
                if let Some(pid) = text
                    .strip_suffix(')')
                    .and_then(|t| t.rsplit_once("(pid "))
                    .and_then(|(head, pid)| head.starts_with("agent process").then_some(pid))
                    .and_then(|pid| pid.parse().ok())
                {
                    self.pids.push(pid);
                }
            }
            Event::Progress(f) => {
                if let Some((at, which)) = self.kill_at
                    && f >= at
                    && self.killed.is_none()
                    && let Some(&pid) = self.pids.get(which)
                {
                    let status = std::process::Command::new("kill")
                        .args(["-9", &pid.to_string()])
                        .status();
                    assert!(status.is_ok_and(|s| s.success()), "kill -9 {pid}");
                    self.killed = Some(pid);
                }
            }
            _ => {}
        }
    }
}

/// Whether process `pid` still runs (a zombie waiting for its parent does not).
fn running(pid: u32) -> bool {
    match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
        Ok(stat) => stat
            .rsplit_once(") ")
            .is_some_and(|(_, rest)| !rest.starts_with('Z')),
        Err(_) => false,
    }
}

fn assert_all_gone(pids: &[u32]) {
    let deadline = Instant::now() + Duration::from_secs(10);
    while pids.iter().any(|&p| running(p)) && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
    }
    let left: Vec<u32> = pids.iter().copied().filter(|&p| running(p)).collect();
    assert!(left.is_empty(), "processes left behind: {left:?}");
}

fn distributed_run(m: &Mission, seed: u64, processes: usize) -> (FleetOutcome, Vec<u32>) {
    let mut watcher = Watcher::default();
    let outcome = distributed::coordinate(
        m,
        seed,
        &options(processes),
        &mut watcher,
        &CancelToken::new(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        watcher.pids.len(),
        processes,
        "one pid per process in the log"
    );
    assert_all_gone(&watcher.pids);
    (outcome, watcher.pids)
}

fn in_process(m: &Mission, seed: u64) -> FleetOutcome {
    fleet::plan(m, seed, &mut Silent, &CancelToken::new()).unwrap_or_else(|e| panic!("{e}"))
}

/// Lockstep over Zenoh, three agents in three processes, flies the
/// in-process fleet bit for bit: every sample, decision, closest approach
/// and message count; with the ideal network and with a late, lossy one
/// where agent 2 decides on a clock of its own.
#[test]
fn lockstep_over_zenoh_is_the_in_process_run_bit_for_bit() {
    let ideal = triangle(6.0);
    let mut lossy = ideal.clone();
    lossy.fleet.network.latency = 3;
    lossy.fleet.network.loss = 0.2;
    // An agent on a clock of its own: every process reads it from the mission.
    lossy.fleet.network.updates = vec![skyform::mission::FleetUpdate {
        agent: 2,
        period: 30,
        phase: 7,
    }];
    for (m, seed) in [(ideal, 3), (lossy, 5)] {
        let here = in_process(&m, seed);
        let (mut there, _) = distributed_run(&m, seed, 3);
        let d = there
            .distributed
            .take()
            .unwrap_or_else(|| panic!("no transport figures"));
        assert_eq!((d.processes, d.clock.as_str()), (3, "lockstep"));
        let steps = (m.fleet.duration.unwrap_or(0.0) / m.fleet.sim_step).round() + 1.0;
        assert!(d.messages as f64 >= 3.0 * steps, "{} messages", d.messages);
        assert!(there.lost.is_empty());
        assert!(
            here.agents
                .iter()
                .all(|a| a.decisions > 0 && a.network.sent > 0)
        );
        if m.fleet.network.loss > 0.0 {
            assert!(here.agents.iter().any(|a| a.network.lost > 0));
        }
        assert_eq!(there, here, "seed {seed}");
    }
}

/// An agent process killed (-9) mid-run is noticed through its liveliness
/// token: it is reported lost with its time, the others fly on to the end,
/// and no process is left.
#[test]
fn a_killed_agent_process_is_reported_lost_and_the_run_finishes() {
    let m = triangle(6.0);
    let mut watcher = Watcher {
        kill_at: Some((0.4, 1)),
        ..Watcher::default()
    };
    let outcome = distributed::coordinate(&m, 3, &options(3), &mut watcher, &CancelToken::new())
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(watcher.killed.is_some(), "the agent was killed");
    assert_eq!(outcome.header.completion, Completion::Finished);
    assert_eq!(outcome.lost.len(), 1, "{:?}", outcome.lost);
    let lost = &outcome.lost[0];
    assert_eq!(lost.agent, 1, "agent 2 (the second process)");
    assert!(
        (2.0..6.0).contains(&lost.time),
        "lost at t = {} s (killed 40 % through 6 s)",
        lost.time
    );
    assert!(lost.reason.contains("went away"), "{}", lost.reason);
    // Its samples stop where it was lost; the others' go on to the end.
    let last = |i: usize| outcome.agents[i].samples.last().map_or(0.0, |s| s.t);
    assert!(last(1) <= lost.time + 1e-9);
    assert!((last(0) - 6.0).abs() < 1e-9 && (last(2) - 6.0).abs() < 1e-9);
    assert!(outcome.agents[0].decisions > 0 && outcome.agents[2].decisions > 0);
    // Its effort is what it did until it was lost (its process never
    // reported): the rounds' count, one decision per τ at least.
    let tau = m.fleet.replan_period;
    let decided = outcome.agents[1].decisions as f64;
    assert!(
        decided >= (lost.time / tau).floor() && decided < outcome.agents[0].decisions as f64,
        "agent 2 decided {decided} times in {} s",
        lost.time
    );
    let per = m.fleet.swarm_size * (m.fleet.iterations + 1);
    assert_eq!(
        outcome.agents[1].evaluations,
        outcome.agents[1].decisions * per
    );
    // The survivors kept clear of where it was last heard, and the one
    // closest approach is over every pair, its own too.
    let c = m.fleet.safety_distance;
    let mut all = f64::INFINITY;
    for d in &outcome.distances {
        for (v, t) in d.values.iter().zip(&outcome.times) {
            all = all.min(*v);
            if (d.a == 1 || d.b == 1) && *t > lost.time {
                assert!(*v >= c, "pair {}-{} at {t} s: {v} m", d.a + 1, d.b + 1);
            }
        }
    }
    assert_eq!(
        outcome.closest_agents.as_ref().map(|c| c.distance),
        Some(all)
    );
    assert_all_gone(&watcher.pids);
}

/// An agent process flying another mission is refused at its hello with
/// both named: an error, not a hang; it exits too.
#[test]
fn an_agent_on_another_mission_is_refused_with_both_named() {
    let m = triangle(2.0);
    let dir = match tempfile::tempdir() {
        Ok(d) => d,
        Err(e) => panic!("{e}"),
    };
    // A stand-in for the agent program: the real one, on another mission.
    let script = dir.path().join("agent.sh");
    let other = dir.path().join("other.toml");
    let mut changed = m.clone();
    changed.name = "Another fleet".into();
    let toml = match mission::to_toml_string(&changed) {
        Ok(t) => t,
        Err(e) => panic!("{e}"),
    };
    if let Err(e) = std::fs::write(&other, toml) {
        panic!("{e}");
    }
    let wrapper = format!(
        "#!/bin/sh\nshift 2\nexec '{}' agent '{}' \"$@\"\n",
        skyform().display(),
        other.display()
    );
    if let Err(e) = std::fs::write(&script, wrapper) {
        panic!("{e}");
    }
    let _ = std::process::Command::new("chmod")
        .args(["+x"])
        .arg(&script)
        .status();
    let mut opts = options(1);
    opts.program = script;
    let mut watcher = Watcher::default();
    let started = Instant::now();
    let result = distributed::coordinate(&m, 3, &opts, &mut watcher, &CancelToken::new());
    let Err(PipelineError::Transport(reason)) = result else {
        panic!("expected a refusal, got {result:?}");
    };
    assert!(reason.contains("refused"), "{reason}");
    assert!(
        reason.contains("Another fleet") && reason.contains("Fleet triangle"),
        "{reason}"
    );
    assert!(
        started.elapsed() < Duration::from_secs(15),
        "refused, not timed out"
    );
    assert_all_gone(&watcher.pids);
}

/// A coordinator killed (-9) leaves no agent process behind: they see its
/// token go and exit.
#[test]
fn agents_exit_when_their_coordinator_dies() {
    let dir = match tempfile::tempdir() {
        Ok(d) => d,
        Err(e) => panic!("{e}"),
    };
    let file = dir.path().join("fleet.toml");
    let toml = match mission::to_toml_string(&triangle(60.0)) {
        Ok(t) => t,
        Err(e) => panic!("{e}"),
    };
    if let Err(e) = std::fs::write(&file, toml) {
        panic!("{e}");
    }
    let mut coordinator = match std::process::Command::new(skyform())
        .args(["run", "fleet"])
        .arg(&file)
        .args(["--distributed", "2"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
    {
        Ok(c) => c,
        Err(e) => panic!("{e}"),
    };
    // Read its log until both agent processes are named and the run is under way.
    let Some(stderr) = coordinator.stderr.take() else {
        panic!("no stderr")
    };
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        use std::io::BufRead;
        for line in std::io::BufReader::new(stderr)
            .lines()
            .map_while(Result::ok)
        {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let mut pids = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(30);
    let mut flying = false;
    while !(flying && pids.len() == 2) && Instant::now() < deadline {
        let Ok(line) = rx.recv_timeout(Duration::from_millis(100)) else {
            continue;
        };
        if let Some(pid) = line
            .strip_suffix(')')
            .and_then(|t| t.rsplit_once("(pid "))
            .and_then(|(_, pid)| pid.parse::<u32>().ok())
            && line.contains("agent process")
        {
            pids.push(pid);
        }
        flying |= line.contains("ready in");
    }
    let _ = coordinator.kill();
    let _ = coordinator.wait();
    assert_eq!(pids.len(), 2, "both agent processes named in the log");
    assert!(flying, "the run started");
    assert_all_gone(&pids);
}

/// On the wall clock every process steps on its own timer: not
/// reproducible, verified the same way. The fleet keeps apart, forms
/// round its target, and every agent decided on neighbour states that had
/// really travelled (older than nothing, younger than a second).
#[test]
fn on_the_wall_clock_the_fleet_flies_and_says_how_old_its_news_was() {
    let m = triangle(16.0);
    let mut opts = options(3);
    opts.realtime = true;
    let mut watcher = Watcher::default();
    let started = Instant::now();
    let outcome = distributed::coordinate(&m, 3, &opts, &mut watcher, &CancelToken::new())
        .unwrap_or_else(|e| panic!("{e}"));
    let wall = started.elapsed().as_secs_f64();
    assert!(
        (16.0..30.0).contains(&wall),
        "flown in real time: {wall:.1} s"
    );
    let d = outcome.distributed.as_ref().map(|d| d.clock.clone());
    assert_eq!(d.as_deref(), Some("realtime"));
    assert!(
        outcome.kept_apart() && outcome.obstacles_clear(),
        "{:?}",
        outcome.closest_agents
    );
    assert!(outcome.converged(), "{:?}", outcome.targets);
    for a in &outcome.agents {
        let n = &a.network;
        assert!(
            n.sent > 1000 && n.received > 1000,
            "agent {}: {n:?}",
            a.index + 1
        );
        assert!(
            n.mean_age > 0.0 && n.worst_age < 1.0,
            "agent {}: {n:?}",
            a.index + 1
        );
        assert!(
            a.decisions > 50,
            "agent {} decided {} times",
            a.index + 1,
            a.decisions
        );
    }
    assert_all_gone(&watcher.pids);
}

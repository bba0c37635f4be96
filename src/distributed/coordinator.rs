//! The coordinator (`skyform run fleet --distributed P`): the hub the agent
//! processes connect to, the simulation clock, and the record of the run.
//!
//! It listens on a free port of 127.0.0.1, starts P agent processes (the
//! fleet's agents split into P ranges), checks each one's hello (the same
//! mission and seed, by fingerprint; a mismatch is refused with both names),
//! waits for every agent's liveliness token and starts the run. Lockstep,
//! each step it waits for every live agent's state, announces the round
//! (with the agents whose token went away, lost from this step), and records
//! the step from the states, as the in-process run records its own. At the
//! end it asks for the agents' reports and waits for every process to exit;
//! any left after a grace period is killed, so no process outlives a run.

use std::io::BufRead;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use zenoh::Wait;
use zenoh::handlers::{FifoChannel, FifoChannelHandler};
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::sample::{Sample, SampleKind};

use super::inbox::{Inbox, drop_lost, missing};
use super::realtime::pace;
use super::session;
use super::wire::{Clock, Control, Hello, Keys, Report, chunk, fingerprint, ids_text};
use crate::mission::Mission;
use crate::pipelines::fleet::network::Message;
use crate::pipelines::fleet::simulation::{Delivery, Effort, Link, LinkError, Simulation};
use crate::pipelines::fleet::{self, Distributed, FleetOutcome};
use crate::pipelines::{CancelToken, Completion, Event, Level, Observer, PipelineError};

/// How a distributed run is carried out.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Agent processes to start (at most one per agent).
    pub processes: usize,
    /// Each process on its own wall clock instead of the coordinator's steps.
    pub realtime: bool,
    /// The `skyform` executable the agent processes run.
    pub program: PathBuf,
    /// Longest wait for any process (to start, to answer a step).
    pub timeout: Duration,
}

impl Options {
    /// `processes` agent processes of this very executable, lockstep.
    pub fn new(processes: usize) -> Self {
        Options {
            processes,
            realtime: false,
            program: std::env::current_exe().unwrap_or_else(|_| PathBuf::from("skyform")),
            timeout: Duration::from_secs(20),
        }
    }
}

/// Subscriptions' queues: a few rounds of the largest fleet.
const QUEUE: usize = 1 << 14;

/// An agent process started by the coordinator, and what it wrote on stderr.
struct Spawned {
    child: Child,
    ids: Vec<usize>,
    log: Arc<Mutex<Vec<String>>>,
}

/// The agent processes of a run: whatever happens, none outlives it (those
/// still running when it is dropped are killed and reaped).
struct Processes {
    spawned: Vec<Spawned>,
}

impl Processes {
    /// The processes that exited, with how, and the last lines they wrote.
    fn exited(&mut self) -> Vec<String> {
        let mut out = Vec::new();
        for s in &mut self.spawned {
            if let Ok(Some(status)) = s.child.try_wait() {
                let tail = s
                    .log
                    .lock()
                    .map(|l| {
                        l.iter()
                            .rev()
                            .take(3)
                            .rev()
                            .cloned()
                            .collect::<Vec<_>>()
                            .join(" | ")
                    })
                    .unwrap_or_default();
                out.push(format!(
                    "the process of agents {} (pid {}) exited ({status}){}",
                    ids_text(&s.ids),
                    s.child.id(),
                    if tail.is_empty() {
                        String::new()
                    } else {
                        format!(": {tail}")
                    }
                ));
            }
        }
        out
    }

    /// Waits up to `grace` for every process to exit; kills the others.
    fn end(&mut self, grace: Duration) {
        let deadline = Instant::now() + grace;
        for s in &mut self.spawned {
            loop {
                match s.child.try_wait() {
                    Ok(Some(_)) | Err(_) => break,
                    Ok(None) if Instant::now() < deadline => {
                        std::thread::sleep(Duration::from_millis(10));
                    }
                    Ok(None) => {
                        let _ = s.child.kill();
                        let _ = s.child.wait();
                        break;
                    }
                }
            }
        }
    }

    /// Every line the processes wrote, tagged with their agents.
    fn lines(&self) -> Vec<String> {
        self.spawned
            .iter()
            .flat_map(|s| {
                let lines = s.log.lock().map(|l| l.clone()).unwrap_or_default();
                let ids = ids_text(&s.ids);
                lines
                    .into_iter()
                    .map(move |line| format!("agents {ids}: {line}"))
            })
            .collect()
    }
}

impl Drop for Processes {
    fn drop(&mut self) {
        self.end(Duration::ZERO);
    }
}

/// The fleet's agents (0-based) split into `processes` ranges, as even as
/// they go.
pub fn split(agents: usize, processes: usize) -> Vec<Vec<usize>> {
    let p = processes.clamp(1, agents.max(1));
    (0..p)
        .map(|k| (k * agents / p..(k + 1) * agents / p).collect())
        .filter(|r: &Vec<usize>| !r.is_empty())
        .collect()
}

/// Flies `mission`'s fleet with `seed` over agent processes, as `options`
/// says; the outcome is the in-process run's, with the transport's figures.
///
/// Long (~225 lines) because it is one run's life in order (subscriptions and tokens, the
/// agents' mission file, spawning, handshake, flight, reports, shutdown), each step holding
/// the session, subscribers and processes the later ones need; the `Processes` guard ends
/// the agents on every early return.
pub fn coordinate(
    mission: &Mission,
    seed: u64,
    options: &Options,
    observer: &mut dyn Observer,
    cancel: &CancelToken,
) -> Result<FleetOutcome, PipelineError> {
    crate::pipelines::require_admissible(mission, fleet::budget)?;
    let fail = PipelineError::Transport;
    if options.processes == 0 {
        return Err(fail("at least one agent process is needed".into()));
    }
    let began = Instant::now();
    observer.on_event(Event::Stage("agent processes"));
    let (session, endpoint) = session::local_hub().map_err(fail)?;
    let run = chunk(&format!(
        "{}-{}",
        std::process::id(),
        began.elapsed().as_nanos() ^ u128::from(seed)
    ));
    let keys = Keys::new(&mission.name, &run);
    let z = |what: &str| {
        let what = what.to_owned();
        move |e: zenoh::Error| PipelineError::Transport(format!("{what}: {e}"))
    };
    let states = session
        .declare_subscriber(keys.states())
        .with(FifoChannel::new(QUEUE))
        .wait()
        .map_err(z("subscribing to the states"))?;
    let hellos = session
        .declare_subscriber(keys.hellos_of_run())
        .with(FifoChannel::new(1024))
        .wait()
        .map_err(z("subscribing to the hellos"))?;
    let reports = session
        .declare_subscriber(keys.report())
        .with(FifoChannel::new(1024))
        .wait()
        .map_err(z("subscribing to the reports"))?;
    let alive = session
        .liveliness()
        .declare_subscriber(keys.alive_agents())
        .history(true)
        .wait()
        .map_err(z("watching the agents"))?;
    let _token = session
        .liveliness()
        .declare_token(keys.alive_coordinator())
        .wait()
        .map_err(z("declaring the coordinator's token"))?;
    let clock = session
        .declare_publisher(keys.clock())
        .congestion_control(CongestionControl::Block)
        .express(true)
        .wait()
        .map_err(z("declaring the clock"))?;

    // The agents load the very mission flown here (terrain aside: the fleet
    // does not read it), from a file that lives as long as the run.
    let mut copy = mission.clone();
    copy.terrain = None;
    let text = crate::mission::to_toml_string(&copy).map_err(|e| fail(e.to_string()))?;
    let file = tempfile::Builder::new()
        .prefix("skyform-fleet-")
        .suffix(".toml")
        .tempfile()
        .map_err(|e| fail(format!("cannot write the agents' mission: {e}")))?;
    std::fs::write(file.path(), text)
        .map_err(|e| fail(format!("cannot write the agents' mission: {e}")))?;

    let groups = split(mission.fleet.agents, options.processes);
    let mut processes = Processes {
        spawned: Vec::new(),
    };
    for ids in &groups {
        let mut command = Command::new(&options.program);
        command
            .arg("agent")
            .arg(file.path())
            .args(["--ids", &ids_text(ids)])
            .args(["--connect", &endpoint])
            .args(["--run", &run])
            .args(["--seed", &seed.to_string()])
            .args(["--timeout", &format!("{}", options.timeout.as_secs_f64())])
            .env(super::agent::SPAWNED_BY, std::process::id().to_string())
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped());
        if options.realtime {
            command.arg("--realtime");
        }
        let mut child = command.spawn().map_err(|e| {
            fail(format!(
                "cannot start an agent process ({}): {e}",
                options.program.display()
            ))
        })?;
        let log = Arc::new(Mutex::new(Vec::new()));
        if let Some(stderr) = child.stderr.take() {
            let log = Arc::clone(&log);
            std::thread::spawn(move || {
                for line in std::io::BufReader::new(stderr)
                    .lines()
                    .map_while(Result::ok)
                {
                    if let Ok(mut l) = log.lock() {
                        l.push(line);
                    }
                }
            });
        }
        let text = format!(
            "agent process {} of {}: agents {} (pid {})",
            processes.spawned.len() + 1,
            groups.len(),
            ids_text(ids),
            child.id()
        );
        observer.on_event(Event::Log(Level::Info, &text));
        processes.spawned.push(Spawned {
            child,
            ids: ids.clone(),
            log,
        });
    }

    let ready = handshake(
        mission,
        seed,
        options,
        &hellos,
        &alive,
        &session,
        &keys,
        &mut processes,
        observer,
    );
    if let Err(e) = ready {
        let _ = clock.put(end("refused")).wait();
        processes.end(Duration::from_secs(2));
        return Err(e);
    }
    let startup = began.elapsed().as_secs_f64();
    observer.on_event(Event::Log(
        Level::Info,
        &format!(
            "{} agent process(es) ready in {startup:.2} s; {} clock",
            groups.len(),
            if options.realtime {
                "each on its own wall"
            } else {
                "lockstep on the coordinator's"
            }
        ),
    ));
    clock
        .put(Clock::Control(Control::Start).encode())
        .wait()
        .map_err(z("starting the run"))?;
    observer.on_event(Event::Vehicles {
        alive: mission.fleet.agents,
        total: mission.fleet.agents,
    });

    observer.on_event(Event::Stage("flight"));
    let mut simulation = Simulation::flying(mission, seed, Vec::new(), true);
    let agents = mission.fleet.agents;
    let mut link = Hub {
        inbox: Inbox::new(&states, agents),
        alive: &alive,
        clock: &clock,
        keys: &keys,
        live: vec![true; agents],
        timeout: options.timeout,
        realtime: options.realtime,
        start: Instant::now(),
        dt: simulation.clock().dt,
        rounds: Vec::new(),
    };
    let flown = simulation.run(&mut link, observer, cancel);
    let (rounds, received) = (std::mem::take(&mut link.rounds), link.inbox.received);
    let reason = match &flown {
        Ok(Completion::Finished) => "finished".to_owned(),
        Ok(Completion::Cancelled) => "cancelled".to_owned(),
        Err(e) => format!("failed: {e}"),
    };
    let _ = clock.put(end(&reason)).wait();
    let lost: Vec<usize> = simulation.lost().iter().map(|l| l.agent).collect();
    let effort = collect_reports(&reports, &groups, &lost, options.timeout, &mut processes);
    let _ = clock.put(end(&reason)).wait();
    processes.end(Duration::from_secs(5));
    for line in processes.lines() {
        observer.on_event(Event::Log(Level::Info, &line));
    }
    let completion = flown.map_err(|e| fail(e.to_string()))?;
    let mut outcome = simulation.finish(completion, &effort, observer);
    let (mean, worst) = if rounds.is_empty() {
        (0.0, 0.0)
    } else {
        (
            rounds.iter().sum::<f64>() / rounds.len() as f64,
            rounds.iter().copied().fold(0.0, f64::max),
        )
    };
    outcome.distributed = Some(Distributed {
        processes: groups.len(),
        clock: if options.realtime {
            "realtime"
        } else {
            "lockstep"
        }
        .into(),
        startup,
        round_mean: mean,
        round_worst: worst,
        messages: received,
    });
    drop(file);
    let _ = session.close().wait();
    Ok(outcome)
}

fn end(reason: &str) -> Vec<u8> {
    Clock::Control(Control::End {
        reason: reason.to_owned(),
    })
    .encode()
}

/// Waits for every process's hello (the right mission and seed) and every
/// agent's liveliness token.
#[allow(clippy::too_many_arguments)]
fn handshake(
    mission: &Mission,
    seed: u64,
    options: &Options,
    hellos: &Subscriber<FifoChannelHandler<Sample>>,
    alive: &Subscriber<FifoChannelHandler<Sample>>,
    session: &zenoh::Session,
    keys: &Keys,
    processes: &mut Processes,
    observer: &mut dyn Observer,
) -> Result<(), PipelineError> {
    let fail = PipelineError::Transport;
    let want = fingerprint(mission, seed);
    let agents = mission.fleet.agents;
    let mut said = vec![false; agents];
    let mut token = vec![false; agents];
    let deadline = Instant::now() + options.timeout;
    while said.iter().chain(&token).any(|&s| !s) {
        let exited = processes.exited();
        if !exited.is_empty() {
            return Err(fail(exited.join("; ")));
        }
        if Instant::now() > deadline {
            let silent: Vec<usize> = (0..agents).filter(|&i| !said[i] || !token[i]).collect();
            return Err(fail(format!(
                "agents {} did not report ready within {:.0} s",
                ids_text(&silent),
                options.timeout.as_secs_f64()
            )));
        }
        while let Ok(Some(s)) = alive.try_recv() {
            if let (SampleKind::Put, Some(i)) = (s.kind(), keys.agent_of(s.key_expr().as_str()))
                && i < agents
            {
                token[i] = true;
            }
        }
        let Ok(Some(sample)) = hellos.recv_timeout(Duration::from_millis(20)) else {
            continue;
        };
        let hello: Hello = match serde_json::from_slice(&sample.payload().to_bytes()) {
            Ok(h) => h,
            Err(e) => return Err(fail(format!("a hello that does not read: {e}"))),
        };
        if hello.fingerprint != want || hello.seed != seed {
            let reason = format!(
                "it flies '{}' with seed {} (fingerprint {:016x}), this run flies '{}' with seed {seed} ({want:016x})",
                hello.mission, hello.seed, hello.fingerprint, mission.name
            );
            // On the clock of the process's own keys (its mission's name
            // may differ from this run's).
            let their_clock = sample
                .key_expr()
                .as_str()
                .strip_suffix("/hello")
                .map_or_else(|| keys.clock(), |prefix| format!("{prefix}/clock"));
            let refusal = Clock::Control(Control::Refuse {
                ids: hello.ids.clone(),
                reason: reason.clone(),
            });
            let _ = session
                .put(their_clock, refusal.encode())
                .congestion_control(CongestionControl::Block)
                .wait();
            return Err(fail(format!(
                "the process of agents {} (pid {}) was refused: {reason}",
                ids_text(&hello.ids),
                hello.pid
            )));
        }
        for &i in &hello.ids {
            if i >= agents || said[i] {
                return Err(fail(format!(
                    "agent {} is claimed twice or is not in the fleet of {agents}",
                    i + 1
                )));
            }
            said[i] = true;
        }
        observer.on_event(Event::Log(
            Level::Info,
            &format!(
                "agents {} (pid {}) said hello",
                ids_text(&hello.ids),
                hello.pid
            ),
        ));
    }
    Ok(())
}

/// The reports of the processes still running (their agents' effort), for
/// up to `timeout`.
fn collect_reports(
    reports: &Subscriber<FifoChannelHandler<Sample>>,
    groups: &[Vec<usize>],
    lost: &[usize],
    timeout: Duration,
    processes: &mut Processes,
) -> Vec<Effort> {
    let mut effort = Vec::new();
    let mut waiting: Vec<&Vec<usize>> = groups
        .iter()
        .filter(|g| g.iter().all(|i| !lost.contains(i)))
        .collect();
    let deadline = Instant::now() + timeout;
    let mut file = |sample: Sample, waiting: &mut Vec<&Vec<usize>>| {
        if let Ok(report) = serde_json::from_slice::<Report>(&sample.payload().to_bytes()) {
            waiting.retain(|g| !report.effort.iter().any(|e| g.contains(&e.agent)));
            effort.extend(report.effort);
        }
    };
    while !waiting.is_empty() && Instant::now() < deadline {
        let all_exited = processes
            .spawned
            .iter_mut()
            .all(|s| matches!(s.child.try_wait(), Ok(Some(_))));
        if let Ok(Some(sample)) = reports.recv_timeout(Duration::from_millis(20)) {
            file(sample, &mut waiting);
        } else if all_exited {
            break; // nobody is left to report
        }
    }
    effort
}

/// The coordinator's link: every live agent's state of the step in, the
/// round announced (lockstep); or, on the wall clock, the newest states.
struct Hub<'a> {
    inbox: Inbox<'a>,
    alive: &'a Subscriber<FifoChannelHandler<Sample>>,
    clock: &'a Publisher<'a>,
    keys: &'a Keys,
    live: Vec<bool>,
    timeout: Duration,
    realtime: bool,
    start: Instant,
    dt: f64,
    /// Seconds per round.
    rounds: Vec<f64>,
}

impl Hub<'_> {
    /// The agents whose token went away since the last look.
    fn gone(&mut self) -> Vec<(usize, String)> {
        let mut out = Vec::new();
        while let Ok(Some(s)) = self.alive.try_recv() {
            if let (SampleKind::Delete, Some(i)) =
                (s.kind(), self.keys.agent_of(s.key_expr().as_str()))
                && self.live.get(i).copied().unwrap_or(false)
            {
                self.live[i] = false;
                out.push((
                    i,
                    "its process went away (its liveliness token was withdrawn)".to_owned(),
                ));
            }
        }
        out
    }
}

impl Link for Hub<'_> {
    fn exchange(&mut self, step: usize, _local: &[Message]) -> Result<Delivery, LinkError> {
        let time = step as f64 * self.dt;
        if self.realtime {
            pace(self.start, step, self.dt);
            let lost = self.gone();
            let mut messages = self.inbox.open(step);
            self.inbox.take_newest(&mut messages);
            return Ok(Delivery { messages, lost });
        }
        let began = Instant::now();
        let deadline = began + self.timeout;
        let mut messages = self.inbox.open(step);
        let mut lost = Vec::new();
        loop {
            lost.extend(self.gone());
            let missing = missing(&messages, &self.live);
            if missing.is_empty() {
                break;
            }
            if Instant::now() > deadline {
                return Err(LinkError {
                    step,
                    time,
                    reason: format!(
                        "no state from agents {} within {:.0} s",
                        ids_text(&missing),
                        self.timeout.as_secs_f64()
                    ),
                });
            }
            self.inbox
                .take(step, &mut messages, Duration::from_millis(20));
        }
        drop_lost(&mut messages, &self.live);
        let round = Clock::Round {
            step,
            lost: lost.clone(),
        };
        self.clock
            .put(round.encode())
            .wait()
            .map_err(|e| LinkError {
                step,
                time,
                reason: format!("cannot announce the round: {e}"),
            })?;
        self.rounds.push(began.elapsed().as_secs_f64());
        Ok(Delivery { messages, lost })
    }
}

//! An agent process (`skyform agent`): flies some of the fleet's agents,
//! each deciding from what it hears, and talks to the others over Zenoh.
//!
//! It connects to the coordinator's hub, declares a liveliness token per
//! agent, says hello (its agents and the mission's fingerprint) and waits
//! for the start. Then, each step, it publishes its agents' states, waits for
//! the coordinator's round (every state of the step is in, and who was lost),
//! takes every state of the step off its subscription, and runs the same
//! stages as the in-process simulation for its own agents. It exits when the
//! run ends, when the coordinator's token goes, or when a wait times out
//! (naming the step and the agents it waited for).

use std::time::{Duration, Instant};

use zenoh::Wait;
use zenoh::handlers::{FifoChannel, FifoChannelHandler};
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::sample::Sample;

use super::inbox::{Inbox, drop_lost, missing, publish};
use super::session;
use super::watch::{ENDED, Watch};
use super::wire::{Clock, Control, Hello, Keys, Report, fingerprint, ids_text};
use crate::mission::Mission;
use crate::pipelines::fleet::network::Message;
use crate::pipelines::fleet::simulation::{Delivery, Link, LinkError, Simulation};
use crate::pipelines::{CancelToken, Completion, Silent};

/// How an agent process runs.
#[derive(Debug, Clone)]
pub struct AgentOptions {
    /// The coordinator's hub, `tcp/HOST:PORT`.
    pub connect: String,
    /// The run's name (its keys' prefix).
    pub run: String,
    pub seed: u64,
    /// Longest wait for the coordinator (to start, for a round).
    pub timeout: Duration,
    /// Fly on this process's own clock (`--realtime`).
    pub realtime: bool,
    /// The coordinator's process id when it spawned this agent
    /// ([`SPAWNED_BY`]): the agent also counts the coordinator gone when it
    /// stops being this process's parent, which a `kill -9` does at once
    /// while the token's withdrawal can be missed.
    pub spawned_by: Option<u32>,
}

/// The environment variable in which a coordinator gives the agent
/// processes it spawns its own process id.
pub const SPAWNED_BY: &str = "SKYFORM_COORDINATOR_PID";

/// Subscriptions deliver into bounded queues; these hold a few rounds of the
/// largest fleet (256 agents, a message each).
const QUEUE: usize = 1 << 14;

/// Flies agents `ids` (0-based) of `mission` until the run ends; `Err` names
/// what went wrong (the coordinator refused or went away, a wait timed out).
pub fn fly(mission: &Mission, ids: Vec<usize>, options: &AgentOptions) -> Result<(), String> {
    let keys = Keys::new(&mission.name, &options.run);
    let session = session::client(&options.connect, options.timeout)?;
    let zenoh_error = |what: &str, e: zenoh::Error| format!("{what}: {e}");
    let states = session
        .declare_subscriber(keys.states())
        .with(FifoChannel::new(QUEUE))
        .wait()
        .map_err(|e| zenoh_error("subscribing to the states", e))?;
    let clock = session
        .declare_subscriber(keys.clock())
        .with(FifoChannel::new(QUEUE))
        .wait()
        .map_err(|e| zenoh_error("subscribing to the clock", e))?;
    let coordinator = session
        .liveliness()
        .declare_subscriber(keys.alive_coordinator())
        .history(true)
        .wait()
        .map_err(|e| zenoh_error("watching the coordinator", e))?;
    let mut tokens = Vec::new();
    for &id in &ids {
        tokens.push(
            session
                .liveliness()
                .declare_token(keys.alive_agent(id))
                .wait()
                .map_err(|e| zenoh_error("declaring the agent's token", e))?,
        );
    }
    let publisher = session
        .declare_publisher(keys.states_of(&ids))
        .congestion_control(CongestionControl::Block)
        .express(true)
        .wait()
        .map_err(|e| zenoh_error("declaring the states publisher", e))?;
    let hello = Hello {
        ids: ids.clone(),
        fingerprint: fingerprint(mission, options.seed),
        mission: mission.name.clone(),
        seed: options.seed,
        pid: std::process::id(),
    };
    say(&session, keys.hello(), &hello, "saying hello")?;

    let mut watch = Watch::new(&coordinator, options.spawned_by);
    wait_for_start(&clock, &mut watch, &ids, options.timeout)?;
    let mut simulation = Simulation::flying(mission, options.seed, ids.clone(), false);
    let (flown, received) = if options.realtime {
        let mut link = super::realtime::AgentClock::new(
            &publisher,
            &states,
            &clock,
            &mut watch,
            mission.fleet.agents,
            &ids,
            simulation.clock().dt,
        );
        let flown = simulation.run(&mut link, &mut Silent, &CancelToken::new());
        (flown, link.inbox.received)
    } else {
        let mut link = Lockstep {
            publisher: &publisher,
            inbox: Inbox::new(&states, mission.fleet.agents),
            clock: &clock,
            watch: &mut watch,
            alive: vec![true; mission.fleet.agents],
            timeout: options.timeout,
        };
        let flown = simulation.run(&mut link, &mut Silent, &CancelToken::new());
        (flown, link.inbox.received)
    };
    let ended_early = match flown {
        Ok(Completion::Finished) => None,
        Ok(Completion::Cancelled) => Some("cancelled".to_owned()),
        Err(e) if e.reason.starts_with(ENDED) => Some(e.reason),
        Err(e) => return Err(format!("agents {}: {e}", ids_text(&ids))),
    };
    let report = Report {
        effort: simulation.effort(),
        received,
    };
    say(&session, keys.report(), &report, "reporting")?;
    if ended_early.is_none() {
        // The coordinator ends the run once every report is in.
        let deadline = Instant::now() + options.timeout;
        while Instant::now() < deadline && !watch.gone() {
            match clock.recv_timeout(Duration::from_millis(50)) {
                Ok(Some(s)) => {
                    if let Ok(Clock::Control(Control::End { .. })) = decode_clock(&s) {
                        break;
                    }
                }
                Ok(None) => {}
                Err(_) => break,
            }
        }
    }
    drop(tokens);
    let _ = session.close().wait();
    Ok(())
}

/// Puts `value` as JSON on `key`, blocking rather than dropping it (the
/// coordinator waits for the hello and the report); `what` names the step
/// in the error.
fn say(
    session: &zenoh::Session,
    key: String,
    value: &impl serde::Serialize,
    what: &str,
) -> Result<(), String> {
    let text = serde_json::to_vec(value).map_err(|e| format!("{what}: {e}"))?;
    session
        .put(key, text)
        .congestion_control(CongestionControl::Block)
        .wait()
        .map_err(|e| format!("{what}: {e}"))
}
fn decode_clock(sample: &Sample) -> Result<Clock, String> {
    Clock::decode(&sample.payload().to_bytes())
}

/// Waits for the coordinator's start; a refusal naming one of `ids` is an
/// error with its reason.
fn wait_for_start(
    clock: &Subscriber<FifoChannelHandler<Sample>>,
    watch: &mut Watch<'_>,
    ids: &[usize],
    timeout: Duration,
) -> Result<(), String> {
    let deadline = Instant::now() + timeout;
    loop {
        if watch.gone() {
            return Err("the coordinator went away before the start".into());
        }
        if Instant::now() > deadline {
            return Err(if watch.seen() {
                format!(
                    "the coordinator did not start the run within {:.0} s",
                    timeout.as_secs_f64()
                )
            } else {
                format!(
                    "no coordinator answered within {:.0} s (is `skyform run fleet --distributed` running, with this mission and run?)",
                    timeout.as_secs_f64()
                )
            });
        }
        let Ok(Some(sample)) = clock.recv_timeout(Duration::from_millis(50)) else {
            continue;
        };
        match decode_clock(&sample)? {
            Clock::Control(Control::Start) => return Ok(()),
            Clock::Control(Control::Refuse {
                ids: refused,
                reason,
            }) if refused.iter().any(|i| ids.contains(i)) => {
                return Err(format!(
                    "the coordinator refused agents {}: {reason}",
                    ids_text(ids)
                ));
            }
            Clock::Control(Control::End { reason }) => {
                return Err(format!("the run ended before it started: {reason}"));
            }
            _ => {}
        }
    }
}

/// The lockstep link of an agent process: publish, wait for the round, take
/// the step's states.
struct Lockstep<'a, 'w> {
    publisher: &'a Publisher<'a>,
    inbox: Inbox<'a>,
    clock: &'a Subscriber<FifoChannelHandler<Sample>>,
    watch: &'a mut Watch<'w>,
    alive: Vec<bool>,
    timeout: Duration,
}

impl Lockstep<'_, '_> {
    fn error(&self, step: usize, reason: String) -> LinkError {
        LinkError {
            step,
            time: f64::NAN,
            reason,
        }
    }
}

impl Link for Lockstep<'_, '_> {
    fn exchange(&mut self, step: usize, local: &[Message]) -> Result<Delivery, LinkError> {
        publish(self.publisher, step, local).map_err(|e| self.error(step, e))?;
        let mut messages = self.inbox.open(step);
        // The round: every state of the step reached the coordinator.
        let deadline = Instant::now() + self.timeout;
        let lost = loop {
            if self.watch.gone() {
                return Err(self.error(step, format!("{ENDED}: its token went away")));
            }
            if Instant::now() > deadline {
                return Err(self.error(
                    step,
                    format!(
                        "no round from the coordinator within {:.0} s",
                        self.timeout.as_secs_f64()
                    ),
                ));
            }
            match self.clock.recv_timeout(Duration::from_millis(20)) {
                Ok(Some(sample)) => match decode_clock(&sample) {
                    Ok(Clock::Round { step: s, lost }) if s == step => break lost,
                    Ok(Clock::Round { .. }) => {}
                    Ok(Clock::Control(Control::End { reason })) => {
                        return Err(self.error(step, format!("{ENDED}: {reason}")));
                    }
                    Ok(Clock::Control(_)) => {}
                    Err(e) => return Err(self.error(step, e)),
                },
                Ok(None) => {}
                Err(e) => return Err(self.error(step, format!("the clock closed: {e}"))),
            }
        };
        for (agent, _) in &lost {
            if let Some(a) = self.alive.get_mut(*agent) {
                *a = false;
            }
        }
        // The states themselves: on their way, or already here.
        for m in local {
            messages[m.sender] = Some(*m);
        }
        loop {
            let missing = missing(&messages, &self.alive);
            if missing.is_empty() {
                break;
            }
            if Instant::now() > deadline {
                return Err(self.error(
                    step,
                    format!("the states of agents {} never came", ids_text(&missing)),
                ));
            }
            self.inbox
                .take(step, &mut messages, Duration::from_millis(20));
        }
        drop_lost(&mut messages, &self.alive);
        Ok(Delivery { messages, lost })
    }
}

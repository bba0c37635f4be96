//! The wall clock (`--realtime`): every process steps on its own timer, as
//! agents onboard would. Each step it publishes its agents' states and takes
//! whatever states have arrived since its last step (the newest of each
//! agent); nobody waits for anybody. Not reproducible (the network's real
//! timing decides what is heard when); the run is verified as any other
//! (closest approaches, formations, the age of what each agent decided on).

use std::time::{Duration, Instant};

use zenoh::Wait;
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::sample::Sample;

use super::agent::{ENDED, Watch};
use super::wire::{Clock, Control, States};
use crate::pipelines::fleet::network::Message;
use crate::pipelines::fleet::simulation::{Delivery, Link, LinkError};

/// Sleeps until step `step` of a clock started at `start` with steps of
/// `dt` seconds is due (at once when it is late).
pub fn pace(start: Instant, step: usize, dt: f64) {
    let due = start + Duration::from_secs_f64(step as f64 * dt);
    let now = Instant::now();
    if due > now {
        std::thread::sleep(due - now);
    }
}

/// The newest state of each agent among those that arrived, into `into`
/// (only states newer than what `into` holds, and than `newest`).
pub fn take_newest(
    states: &Subscriber<FifoChannelHandler<Sample>>,
    into: &mut [Option<Message>],
    newest: &mut [Option<usize>],
) -> usize {
    let mut count = 0;
    while let Ok(Some(sample)) = states.try_recv() {
        let Ok(batch) = States::decode(&sample.payload().to_bytes()) else {
            continue;
        };
        for m in batch.messages {
            count += 1;
            let Some(slot) = newest.get_mut(m.sender) else {
                continue;
            };
            if slot.is_none_or(|s| m.step > s) {
                *slot = Some(m.step);
                into[m.sender] = Some(m);
            }
        }
    }
    count
}

/// An agent process's link on the wall clock.
pub struct AgentClock<'a, 'w> {
    publisher: &'a Publisher<'a>,
    states: &'a Subscriber<FifoChannelHandler<Sample>>,
    clock: &'a Subscriber<FifoChannelHandler<Sample>>,
    watch: &'a mut Watch<'w>,
    agents: usize,
    newest: Vec<Option<usize>>,
    start: Instant,
    dt: f64,
    pub received: usize,
}

impl<'a, 'w> AgentClock<'a, 'w> {
    pub fn new(
        publisher: &'a Publisher<'a>,
        states: &'a Subscriber<FifoChannelHandler<Sample>>,
        clock: &'a Subscriber<FifoChannelHandler<Sample>>,
        watch: &'a mut Watch<'w>,
        agents: usize,
        _ids: &[usize],
        dt: f64,
    ) -> Self {
        AgentClock {
            publisher,
            states,
            clock,
            watch,
            agents,
            newest: vec![None; agents],
            start: Instant::now(),
            dt,
            received: 0,
        }
    }
}

impl Link for AgentClock<'_, '_> {
    fn exchange(&mut self, step: usize, local: &[Message]) -> Result<Delivery, LinkError> {
        let error = |reason: String| LinkError {
            step,
            time: step as f64 * self.dt,
            reason,
        };
        pace(self.start, step, self.dt);
        if self.watch.gone() {
            return Err(error(format!("{ENDED}: its token went away")));
        }
        while let Ok(Some(sample)) = self.clock.try_recv() {
            if let Ok(Clock::Control(Control::End { reason })) =
                Clock::decode(&sample.payload().to_bytes())
            {
                return Err(error(format!("{ENDED}: {reason}")));
            }
        }
        let batch = States {
            step,
            messages: local.to_vec(),
        };
        self.publisher
            .put(batch.encode())
            .wait()
            .map_err(|e| error(format!("cannot publish the states: {e}")))?;
        let mut messages = vec![None; self.agents];
        self.received += take_newest(self.states, &mut messages, &mut self.newest);
        for m in local {
            messages[m.sender] = Some(*m);
            self.newest[m.sender] = Some(m.step);
        }
        Ok(Delivery {
            messages,
            lost: Vec::new(),
        })
    }
}

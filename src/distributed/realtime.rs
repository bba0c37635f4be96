//! The wall clock (`--realtime`): every process steps on its own timer, as
//! agents onboard would. Each step it publishes its agents' states and takes
//! whatever states have arrived since its last step (the newest of each
//! agent); nobody waits for anybody. Not reproducible (the network's real
//! timing decides what is heard when); the run is verified as any other
//! (closest approaches, formations, the age of what each agent decided on).

use std::time::{Duration, Instant};

use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::sample::Sample;

use super::inbox::{Inbox, publish};
use super::watch::{ENDED, Watch};
use super::wire::{Clock, Control};
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

/// An agent process's link on the wall clock.
pub struct AgentClock<'a, 'w> {
    publisher: &'a Publisher<'a>,
    pub inbox: Inbox<'a>,
    clock: &'a Subscriber<FifoChannelHandler<Sample>>,
    watch: &'a mut Watch<'w>,
    start: Instant,
    dt: f64,
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
            inbox: Inbox::new(states, agents),
            clock,
            watch,
            start: Instant::now(),
            dt,
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
        publish(self.publisher, step, local).map_err(error)?;
        let mut messages = self.inbox.open(step);
        self.inbox.take_newest(&mut messages);
        for m in local {
            messages[m.sender] = Some(*m);
            self.inbox.own(m);
        }
        Ok(Delivery {
            messages,
            lost: Vec::new(),
        })
    }
}

//! The agents' states as they come off a subscription, and going out: what
//! every link of a distributed run (an agent process's, the coordinator's,
//! lockstep or on the wall clock) does with them.

use std::collections::BTreeMap;
use std::time::Duration;

use zenoh::Wait;
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::sample::Sample;

use super::wire::States;
use crate::pipelines::fleet::network::Message;

/// The states of one subscription, filed by step.
pub struct Inbox<'a> {
    states: &'a Subscriber<FifoChannelHandler<Sample>>,
    /// States that came ahead of their step.
    pending: BTreeMap<usize, Vec<Message>>,
    /// The newest step heard from each agent (the wall clock's reading).
    newest: Vec<Option<usize>>,
    /// Messages received so far.
    pub received: usize,
}

impl<'a> Inbox<'a> {
    pub fn new(states: &'a Subscriber<FifoChannelHandler<Sample>>, agents: usize) -> Self {
        Inbox {
            states,
            pending: BTreeMap::new(),
            newest: vec![None; agents],
            received: 0,
        }
    }

    /// A step's slots, per agent, with the states of `step` that came early.
    pub fn open(&mut self, step: usize) -> Vec<Option<Message>> {
        let mut into = vec![None; self.newest.len()];
        for m in self.pending.remove(&step).unwrap_or_default() {
            if let Some(slot) = into.get_mut(m.sender) {
                *slot = Some(m);
            }
        }
        into
    }

    /// Waits up to `wait` for states, then takes every one that came: those
    /// of `step` into `into`, later ones kept for their step.
    pub fn take(&mut self, step: usize, into: &mut [Option<Message>], wait: Duration) {
        let mut next = self.states.recv_timeout(wait).ok().flatten();
        while let Some(sample) = next {
            if let Ok(batch) = States::decode(&sample.payload().to_bytes()) {
                self.received += batch.messages.len();
                for m in batch.messages {
                    if m.step == step && m.sender < into.len() {
                        into[m.sender] = Some(m);
                    } else if m.step > step {
                        self.pending.entry(m.step).or_default().push(m);
                    }
                }
            }
            next = self.states.try_recv().ok().flatten();
        }
    }

    /// The wall clock's reading: of the states that came, the newest of
    /// each agent (newer than any read before) into `into`.
    pub fn take_newest(&mut self, into: &mut [Option<Message>]) {
        while let Ok(Some(sample)) = self.states.try_recv() {
            let Ok(batch) = States::decode(&sample.payload().to_bytes()) else {
                continue;
            };
            for m in batch.messages {
                self.received += 1;
                let Some(slot) = self.newest.get_mut(m.sender) else {
                    continue;
                };
                if slot.is_none_or(|s| m.step > s) {
                    *slot = Some(m.step);
                    into[m.sender] = Some(m);
                }
            }
        }
    }

    /// A state of this process's own, as read: later ones are newer.
    pub fn own(&mut self, m: &Message) {
        if let Some(slot) = self.newest.get_mut(m.sender) {
            *slot = Some(m.step);
        }
    }
}

/// The agents still flying (`alive`) whose state of the step is not in.
pub fn missing(messages: &[Option<Message>], alive: &[bool]) -> Vec<usize> {
    (0..messages.len())
        .filter(|&i| alive[i] && messages[i].is_none())
        .collect()
}

/// Forgets the states of agents no longer flying: nobody hears them.
pub fn drop_lost(messages: &mut [Option<Message>], alive: &[bool]) {
    for (m, _) in messages.iter_mut().zip(alive).filter(|(_, a)| !**a) {
        *m = None;
    }
}

/// Publishes this process's agents' states of `step`.
pub fn publish(publisher: &Publisher<'_>, step: usize, local: &[Message]) -> Result<(), String> {
    let batch = States {
        step,
        messages: local.to_vec(),
    };
    publisher
        .put(batch.encode())
        .wait()
        .map_err(|e| format!("cannot publish the states: {e}"))
}

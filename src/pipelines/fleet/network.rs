//! What each agent hears of the others: the messages of the fleet's network
//! (`[fleet.network]`), the same model whichever transport carries them.
//!
//! Every simulation step each agent broadcasts a [`Message`]: its id, the
//! step, its position, velocity and reference. Receiver i hears sender j's
//! message of step s at step s + latency when the two were within `range` at
//! step s and the message is not lost. Loss is a pure function of (seed,
//! sender, receiver, step), so the same mission and seed lose the same
//! messages in any run, in process or over a transport. Each agent keeps the
//! last message heard from each neighbour and decides from that, with its
//! age; with no latency and no loss it is the neighbour's state of this very
//! step, and the run is the one of a perfect snapshot, bit for bit.
//!
//! Only the pairs the simulation watches (each agent's neighbour list, which
//! reaches beyond l) are delivered: the others are out of range of anything
//! the agent uses.

use nalgebra::{Point2, Vector2};
use serde::{Deserialize, Serialize};

use crate::mission::FleetNetwork;

/// One agent's state as it broadcasts it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Message {
    pub sender: usize,
    /// The step it was sent at.
    pub step: usize,
    pub position: Point2<f64>,
    /// Its height, metres (the flight altitude, give or take the flight's
    /// own motion): not used by the neighbours, kept for the record.
    pub height: f64,
    pub velocity: Vector2<f64>,
    pub reference: Point2<f64>,
}

/// One agent's traffic over the run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct LinkStats {
    /// Broadcasts: one per step.
    pub sent: usize,
    /// Messages heard from neighbours in range.
    pub received: usize,
    /// Messages to it from neighbours in range that were lost.
    pub lost: usize,
    /// Over its decisions, the mean and the worst age of what it knew of
    /// the neighbours it used, seconds.
    pub mean_age: f64,
    pub worst_age: f64,
    /// Neighbour states used in decisions (the mean age's count).
    pub used: usize,
}

/// The fleet's network in one process: what was sent, what each heard.
pub struct Network {
    range: f64,
    latency: usize,
    /// Per receiver × sender, the link's own latency where it has one.
    link_latency: std::collections::HashMap<(usize, usize), usize>,
    /// The longest latency of any link: the steps of broadcasts kept.
    longest: usize,
    loss: f64,
    seed: u64,
    agents: usize,
    dt: f64,
    /// The last `latency + 1` steps' broadcasts, oldest first.
    sent: std::collections::VecDeque<Vec<Option<Message>>>,
    /// Per receiver × sender, the last message heard (`None`: never).
    heard: Vec<Option<Message>>,
    stats: Vec<LinkStats>,
}

impl Network {
    /// The network of `model` for `agents` agents, `neighbourhood` the
    /// range when the model gives none; steps of `dt` seconds.
    pub fn new(
        model: &FleetNetwork,
        neighbourhood: f64,
        agents: usize,
        seed: u64,
        dt: f64,
    ) -> Self {
        let mut link_latency = std::collections::HashMap::new();
        for link in &model.links {
            let [a, b] = link.between.map(|k| k.saturating_sub(1));
            link_latency.insert((a, b), link.latency);
            link_latency.insert((b, a), link.latency);
        }
        let longest = link_latency
            .values()
            .copied()
            .fold(model.latency, usize::max);
        Network {
            range: model.range.unwrap_or(neighbourhood),
            latency: model.latency,
            link_latency,
            longest,
            loss: model.loss,
            seed,
            agents,
            dt,
            sent: std::collections::VecDeque::with_capacity(longest + 1),
            heard: vec![None; agents * agents],
            stats: vec![LinkStats::default(); agents],
        }
    }

    /// Step `step`'s broadcasts go out (per agent, in agent order: `None`
    /// for an agent that sent nothing, lost or not heard from), and what
    /// arrives at this step is heard: for each receiver, from the senders in
    /// `watched[receiver]`.
    pub fn exchange(
        &mut self,
        step: usize,
        broadcasts: Vec<Option<Message>>,
        watched: &[Vec<usize>],
    ) {
        for (s, _) in self
            .stats
            .iter_mut()
            .zip(&broadcasts)
            .filter(|(_, m)| m.is_some())
        {
            s.sent += 1;
        }
        self.sent.push_back(broadcasts);
        if self.sent.len() > self.longest + 1 {
            self.sent.pop_front();
        }
        // The broadcasts of `latency` steps ago, if sent yet.
        let sent = &self.sent;
        let of = |latency: usize| {
            step.checked_sub(latency)?;
            sent.get(sent.len().checked_sub(latency + 1)?)
        };
        for (receiver, senders) in watched.iter().enumerate() {
            for &sender in senders {
                let latency = self
                    .link_latency
                    .get(&(receiver, sender))
                    .copied()
                    .unwrap_or(self.latency);
                let Some(arriving) = of(latency) else {
                    continue; // nothing sent long enough ago yet
                };
                // Where the receiver was when it was sent.
                let (Some(at), Some(message)) = (arriving[receiver], arriving[sender]) else {
                    continue;
                };
                let at = at.position;
                if (message.position - at).norm() > self.range {
                    continue;
                }
                if self.loss > 0.0 && lost(self.seed, sender, receiver, message.step, self.loss) {
                    self.stats[receiver].lost += 1;
                    continue;
                }
                self.stats[receiver].received += 1;
                self.heard[receiver * self.agents + sender] = Some(message);
            }
        }
    }

    /// The last message `receiver` heard from `sender`.
    pub fn heard(&self, receiver: usize, sender: usize) -> Option<&Message> {
        self.heard[receiver * self.agents + sender].as_ref()
    }

    /// Counts the age at `step` of a neighbour state `receiver` decided on.
    pub fn used(&mut self, receiver: usize, message: &Message, step: usize) {
        let age = step.saturating_sub(message.step) as f64 * self.dt;
        let s = &mut self.stats[receiver];
        s.used += 1;
        s.mean_age += (age - s.mean_age) / s.used as f64;
        s.worst_age = s.worst_age.max(age);
    }

    /// Each agent's traffic.
    pub fn stats(&self) -> &[LinkStats] {
        &self.stats
    }
}

/// Whether the message of `step` from `sender` to `receiver` is lost: a
/// hash of the four to a uniform number in [0, 1), below `loss`.
pub fn lost(seed: u64, sender: usize, receiver: usize, step: usize, loss: f64) -> bool {
    let mut h = seed ^ 0x9e37_79b9_7f4a_7c15;
    for v in [sender as u64, receiver as u64, step as u64] {
        h = splitmix(h ^ v);
    }
    // The top 53 bits as a fraction of 2^53.
    ((h >> 11) as f64 / (1u64 << 53) as f64) < loss
}

/// SplitMix64's finaliser: every input bit reaches every output bit.
fn splitmix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Loss is a function of (seed, sender, receiver, step) alone, at the
    /// rate asked: the same links lose the same messages in every run.
    #[test]
    fn loss_is_reproducible_and_at_the_rate_asked() {
        let count = |seed: u64| {
            (0..20_000)
                .filter(|&k| lost(seed, k % 7, k % 5, k, 0.3))
                .count()
        };
        let (a, b) = (count(1), count(1));
        assert_eq!(a, b);
        let rate = a as f64 / 20_000.0;
        assert!((rate - 0.3).abs() < 0.02, "lost {rate}");
        assert_ne!(count(2), a, "another seed loses other messages");
        assert!(!lost(1, 0, 1, 5, 0.0));
    }

    fn message(sender: usize, step: usize, x: f64) -> Message {
        Message {
            sender,
            step,
            position: Point2::new(x, 0.0),
            height: 1.0,
            velocity: Vector2::zeros(),
            reference: Point2::new(x, 0.0),
        }
    }

    /// With a latency of 2 steps, step k hears step k − 2; out of range,
    /// nothing; the age of what was used is counted.
    #[test]
    fn a_message_arrives_latency_steps_later_and_only_in_range() {
        let model = FleetNetwork {
            range: Some(5.0),
            latency: 2,
            loss: 0.0,
            links: Vec::new(),
            updates: Vec::new(),
        };
        let mut net = Network::new(&model, 5.0, 3, 7, 0.01);
        let watched = vec![vec![1, 2], vec![0], vec![0]];
        for k in 0..4 {
            // Agent 2 is 10 m away: out of range.
            let out = vec![
                Some(message(0, k, 0.0)),
                Some(message(1, k, 1.0 + k as f64)),
                Some(message(2, k, 10.0)),
            ];
            net.exchange(k, out, &watched);
            match k {
                0 | 1 => assert!(net.heard(0, 1).is_none(), "nothing yet at step {k}"),
                _ => assert_eq!(net.heard(0, 1).map(|m| m.step), Some(k - 2)),
            }
        }
        assert!(net.heard(0, 2).is_none());
        assert_eq!(net.heard(0, 1).map(|m| m.position.x), Some(2.0));
        if let Some(m) = net.heard(0, 1).copied() {
            net.used(0, &m, 3);
        }
        let s = net.stats()[0];
        assert_eq!((s.sent, s.received, s.lost), (4, 2, 0));
        assert!((s.worst_age - 0.02).abs() < 1e-12 && (s.mean_age - 0.02).abs() < 1e-12);
    }

    /// A link with a latency of its own: 1 and 2 hear each other 4 steps
    /// late, 1 hears 3 at the default 1 step.
    #[test]
    fn a_link_can_have_a_latency_of_its_own() {
        let model = FleetNetwork {
            range: None,
            latency: 1,
            loss: 0.0,
            links: vec![crate::mission::FleetLink {
                between: [1, 2],
                latency: 4,
            }],
            updates: Vec::new(),
        };
        let mut net = Network::new(&model, 50.0, 3, 7, 0.01);
        let watched = vec![vec![1, 2], vec![0], vec![0]];
        for k in 0..6 {
            let out = (0..3).map(|i| Some(message(i, k, i as f64))).collect();
            net.exchange(k, out, &watched);
        }
        assert_eq!(net.heard(0, 2).map(|m| m.step), Some(4), "5 − 1");
        assert_eq!(net.heard(0, 1).map(|m| m.step), Some(1), "5 − 4");
        assert_eq!(net.heard(1, 0).map(|m| m.step), Some(1), "both ways");
    }
}

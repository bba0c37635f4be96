//! What the fleet's processes say to each other, and under which keys.
//!
//! Every key is under one prefix per run, `skyform/<mission>/<run>`:
//!
//! | key | from → to | what |
//! | --- | --- | --- |
//! | `…/agent/<ids>/state` | an agent process → all | its agents' states of one step ([`States`], binary) |
//! | `…/clock` | coordinator → agents | a step's round closed ([`Round`], binary), or a [`Control`] (JSON) |
//! | `…/hello` | agent process → coordinator | who it flies and which mission ([`Hello`], JSON) |
//! | `…/report` | agent process → coordinator | its agents' planning effort at the end ([`Report`], JSON) |
//! | `…/alive/agent/<id>` | liveliness token of each agent | gone when its process is |
//! | `…/alive/coordinator` | liveliness token of the coordinator | agents exit when it goes |
//!
//! `<ids>` is `3` for one agent, `1-3` for a range (1-based, as people count
//! vehicles). States and rounds go every step, so they are a few dozen bytes
//! of little-endian numbers; the rest is JSON, readable in a capture.

use serde::{Deserialize, Serialize};

use crate::mission::Mission;
use crate::pipelines::fleet::network::Message;
use crate::pipelines::fleet::simulation::Effort;
use nalgebra::{Point2, Vector2};

/// The keys of one run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Keys {
    pub prefix: String,
}

impl Keys {
    /// The keys of run `run` of `mission` (both made safe for a key: letters,
    /// digits, `-` and `_`).
    pub fn new(mission: &str, run: &str) -> Self {
        Keys {
            prefix: format!("skyform/{}/{}", chunk(mission), chunk(run)),
        }
    }

    /// The states of the agents `ids` (0-based).
    pub fn states_of(&self, ids: &[usize]) -> String {
        format!("{}/agent/{}/state", self.prefix, ids_text(ids))
    }

    /// Every agent's states.
    pub fn states(&self) -> String {
        format!("{}/agent/*/state", self.prefix)
    }

    pub fn clock(&self) -> String {
        format!("{}/clock", self.prefix)
    }

    pub fn hello(&self) -> String {
        format!("{}/hello", self.prefix)
    }

    /// Every hello of this run, whichever mission the process flies (so a
    /// process on another mission is heard, and refused, not left waiting).
    pub fn hellos_of_run(&self) -> String {
        match self.prefix.rsplit_once('/') {
            Some((_, run)) => format!("skyform/*/{run}/hello"),
            None => self.hello(),
        }
    }

    pub fn report(&self) -> String {
        format!("{}/report", self.prefix)
    }

    /// The liveliness token of agent `id` (0-based).
    pub fn alive_agent(&self, id: usize) -> String {
        format!("{}/alive/agent/{}", self.prefix, id + 1)
    }

    pub fn alive_agents(&self) -> String {
        format!("{}/alive/agent/*", self.prefix)
    }

    pub fn alive_coordinator(&self) -> String {
        format!("{}/alive/coordinator", self.prefix)
    }

    /// The agent (0-based) a liveliness key of [`Self::alive_agent`] names.
    pub fn agent_of(&self, key: &str) -> Option<usize> {
        let rest = key.strip_prefix(&format!("{}/alive/agent/", self.prefix))?;
        rest.parse::<usize>().ok()?.checked_sub(1)
    }
}

/// A key chunk: `text` with everything but letters, digits, `-` and `_`
/// replaced by `-` (never empty, never starting with `@`).
pub fn chunk(text: &str) -> String {
    let safe: String = text
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect();
    let safe = safe.trim_matches('-').to_owned();
    if safe.is_empty() { "run".into() } else { safe }
}

/// Agents (0-based) as people write them: `3`, `1-3`, or `1,4,7`.
pub fn ids_text(ids: &[usize]) -> String {
    match ids {
        [] => "none".into(),
        [one] => (one + 1).to_string(),
        _ if ids.windows(2).all(|w| w[1] == w[0] + 1) => {
            format!("{}-{}", ids[0] + 1, ids[ids.len() - 1] + 1)
        }
        _ => ids
            .iter()
            .map(|i| (i + 1).to_string())
            .collect::<Vec<_>>()
            .join(","),
    }
}

/// Reads agent numbers as people write them (`2`, `1-3`, `1,4-6`), 1-based,
/// into 0-based indices, each below `agents`.
pub fn parse_ids(text: &str, agents: usize) -> Result<Vec<usize>, String> {
    let mut ids = Vec::new();
    for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (a, b) = match part.split_once('-') {
            Some((a, b)) => (a.trim(), b.trim()),
            None => (part, part),
        };
        let number = |s: &str| {
            s.parse::<usize>()
                .map_err(|_| format!("'{part}' is not an agent number or a range like 1-3"))
        };
        let (a, b) = (number(a)?, number(b)?);
        if a == 0 || b < a {
            return Err(format!(
                "'{part}': agents are numbered from 1, ranges go up (1-3)"
            ));
        }
        if b > agents {
            return Err(format!(
                "'{part}': the mission's fleet has {agents} agent(s), numbered 1 to {agents}"
            ));
        }
        ids.extend((a - 1)..b);
    }
    ids.sort_unstable();
    ids.dedup();
    if ids.is_empty() {
        return Err("no agents given (e.g. --ids 1-3)".into());
    }
    Ok(ids)
}

/// The agents of one process's states at one step.
#[derive(Debug, Clone, PartialEq)]
pub struct States {
    pub step: usize,
    pub messages: Vec<Message>,
}

/// Bytes of one message on the wire: sender (4), step (8), 7 numbers (56).
const MESSAGE_BYTES: usize = 4 + 8 + 7 * 8;

impl States {
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(1 + 8 + 4 + MESSAGE_BYTES * self.messages.len());
        out.push(b'S');
        out.extend_from_slice(&(self.step as u64).to_le_bytes());
        out.extend_from_slice(&(self.messages.len() as u32).to_le_bytes());
        for m in &self.messages {
            out.extend_from_slice(&(m.sender as u32).to_le_bytes());
            out.extend_from_slice(&(m.step as u64).to_le_bytes());
            for v in [
                m.position.x,
                m.position.y,
                m.height,
                m.velocity.x,
                m.velocity.y,
                m.reference.x,
                m.reference.y,
            ] {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        out
    }

    pub fn decode(bytes: &[u8]) -> Result<Self, String> {
        let mut r = Reader::new(bytes);
        if r.u8()? != b'S' {
            return Err("not a states message".into());
        }
        let step = r.u64()? as usize;
        let count = r.u32()? as usize;
        if r.left() != count * MESSAGE_BYTES {
            return Err(format!(
                "a states message of {count} agent(s) must be {} bytes, got {}",
                count * MESSAGE_BYTES,
                r.left()
            ));
        }
        let mut messages = Vec::with_capacity(count);
        for _ in 0..count {
            let sender = r.u32()? as usize;
            let step = r.u64()? as usize;
            let mut v = [0.0; 7];
            for x in &mut v {
                *x = r.f64()?;
            }
            messages.push(Message {
                sender,
                step,
                position: Point2::new(v[0], v[1]),
                height: v[2],
                velocity: Vector2::new(v[3], v[4]),
                reference: Point2::new(v[5], v[6]),
            });
        }
        Ok(States { step, messages })
    }
}

/// What the coordinator says on the clock key.
#[derive(Debug, Clone, PartialEq)]
pub enum Clock {
    /// Every state of `step` is in: the agents may decide and fly. `lost`
    /// are the agents that went away at this step, with why.
    Round {
        step: usize,
        lost: Vec<(usize, String)>,
    },
    Control(Control),
}

/// The coordinator's orders, rarely sent.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "order", rename_all = "snake_case")]
pub enum Control {
    /// Every agent said hello with the right mission: fly step 0.
    Start,
    /// The agents of `ids` (0-based) cannot join (a different mission): why.
    Refuse { ids: Vec<usize>, reason: String },
    /// The run stops (finished, cancelled, or failed): report and exit.
    End { reason: String },
}

impl Clock {
    pub fn encode(&self) -> Vec<u8> {
        match self {
            Clock::Round { step, lost } => {
                let mut out = vec![b'R'];
                out.extend_from_slice(&(*step as u64).to_le_bytes());
                out.extend_from_slice(&(lost.len() as u32).to_le_bytes());
                for (agent, reason) in lost {
                    out.extend_from_slice(&(*agent as u32).to_le_bytes());
                    out.extend_from_slice(&(reason.len() as u32).to_le_bytes());
                    out.extend_from_slice(reason.as_bytes());
                }
                out
            }
            Clock::Control(c) => {
                let mut out = vec![b'C'];
                out.extend(serde_json::to_vec(c).unwrap_or_default());
                out
            }
        }
    }

    pub fn decode(bytes: &[u8]) -> Result<Self, String> {
        match bytes.first() {
            Some(b'R') => {
                let mut r = Reader::new(&bytes[1..]);
                let step = r.u64()? as usize;
                let count = r.u32()? as usize;
                let mut lost = Vec::with_capacity(count.min(1024));
                for _ in 0..count {
                    let agent = r.u32()? as usize;
                    let len = r.u32()? as usize;
                    let text = String::from_utf8_lossy(r.take(len)?).into_owned();
                    lost.push((agent, text));
                }
                Ok(Clock::Round { step, lost })
            }
            Some(b'C') => serde_json::from_slice(&bytes[1..])
                .map(Clock::Control)
                .map_err(|e| format!("a control message that does not read: {e}")),
            _ => Err("not a clock message".into()),
        }
    }
}

/// An agent process introducing itself.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Hello {
    /// Its agents, 0-based.
    pub ids: Vec<usize>,
    /// [`fingerprint`] of the mission it loaded, and its name.
    pub fingerprint: u64,
    pub mission: String,
    pub seed: u64,
    pub pid: u32,
}

/// An agent process's last word: what its agents did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Report {
    pub effort: Vec<Effort>,
    /// Messages it received over the transport.
    pub received: usize,
}

/// What the fleet pipeline reads of a mission (its name, bounds, obstacles
/// and fleet section) and the seed, hashed (FNV-1a over their JSON): two
/// processes with the same fingerprint fly the same fleet.
pub fn fingerprint(mission: &Mission, seed: u64) -> u64 {
    let parts = serde_json::json!({
        "name": mission.name,
        "bounds": mission.bounds,
        "obstacles": mission.obstacles,
        "fleet": mission.fleet,
        "seed": seed,
    });
    let text = parts.to_string();
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Little-endian numbers off a byte slice, every read checked.
struct Reader<'a> {
    bytes: &'a [u8],
}

impl<'a> Reader<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        Reader { bytes }
    }

    fn left(&self) -> usize {
        self.bytes.len()
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        if self.bytes.len() < n {
            return Err(format!(
                "a message cut short ({} bytes left, {n} needed)",
                self.bytes.len()
            ));
        }
        let (head, tail) = self.bytes.split_at(n);
        self.bytes = tail;
        Ok(head)
    }

    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }

    fn u32(&mut self) -> Result<u32, String> {
        let mut a = [0; 4];
        a.copy_from_slice(self.take(4)?);
        Ok(u32::from_le_bytes(a))
    }

    fn u64(&mut self) -> Result<u64, String> {
        let mut a = [0; 8];
        a.copy_from_slice(self.take(8)?);
        Ok(u64::from_le_bytes(a))
    }

    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_bits(self.u64()?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn message(sender: usize) -> Message {
        Message {
            sender,
            step: 41,
            position: Point2::new(1.5, -2.25),
            height: 1.0000001,
            velocity: Vector2::new(0.1, f64::MIN_POSITIVE),
            reference: Point2::new(3.0, 1e-300),
        }
    }

    /// States and rounds come back bit for bit; a truncated message is an
    /// error, not a panic.
    #[test]
    fn messages_read_back_bit_for_bit() {
        let states = States {
            step: 41,
            messages: vec![message(0), message(2)],
        };
        let bytes = states.encode();
        assert_eq!(States::decode(&bytes), Ok(states));
        assert!(States::decode(&bytes[..bytes.len() - 1]).is_err());
        for clock in [
            Clock::Round {
                step: 7,
                lost: vec![(1, "gone".into())],
            },
            Clock::Control(Control::End {
                reason: "finished".into(),
            }),
        ] {
            assert_eq!(Clock::decode(&clock.encode()), Ok(clock));
        }
        assert!(Clock::decode(b"R\x01").is_err());
    }

    #[test]
    fn agent_numbers_read_as_people_write_them() {
        assert_eq!(parse_ids("1-3", 3), Ok(vec![0, 1, 2]));
        assert_eq!(parse_ids("2, 4-5", 5), Ok(vec![1, 3, 4]));
        assert!(parse_ids("0", 3).unwrap_err().contains("from 1"));
        assert!(parse_ids("2-4", 3).unwrap_err().contains("3 agent(s)"));
        assert!(parse_ids("x", 3).is_err());
        assert_eq!(ids_text(&[0, 1, 2]), "1-3");
        assert_eq!(ids_text(&[4]), "5");
        assert_eq!(ids_text(&[0, 3]), "1,4");
    }

    #[test]
    fn keys_are_one_prefix_per_run_and_safe() {
        let k = Keys::new("Fleet triangle", "r 7/x");
        assert_eq!(k.prefix, "skyform/fleet-triangle/r-7-x");
        assert_eq!(
            k.states_of(&[0, 1]),
            "skyform/fleet-triangle/r-7-x/agent/1-2/state"
        );
        assert_eq!(k.agent_of(&k.alive_agent(4)), Some(4));
        assert_eq!(k.agent_of("skyform/other/alive/agent/1"), None);
        assert_eq!(k.hellos_of_run(), "skyform/*/r-7-x/hello");
    }
}

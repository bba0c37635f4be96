//! The distributed fleet, distributed: each agent process flies some of the
//! fleet's agents and talks to the others over Zenoh (TCP, no scouting).
//!
//! The fleet pipeline itself (`pipelines::fleet`) knows nothing of
//! processes: its simulation hands each step's messages to a `Link`. Here are
//! the links that carry them over Zenoh and the two programs that use them:
//!
//! - the coordinator (`coordinator.rs`, `skyform run fleet --distributed P`):
//!   the hub the agent processes connect to, the simulation clock (lockstep)
//!   and the record of the run;
//! - the agent process (`agent.rs`, `skyform agent`): flies its agents, each
//!   deciding from what it hears through the network model.
//!
//! Lockstep (the default), the run is the in-process run bit for bit for the
//! same mission, seed and network model: every process applies the same
//! model to the same messages. On the wall clock (`realtime.rs`) every
//! process steps on its own timer. What goes over the wire, and under which
//! keys, is `wire.rs`; the sessions' configuration is `session.rs`; how an
//! agent process knows its coordinator is gone, `watch.rs`. The
//! network model and the topics are documented in `docs/fleet.md`.

pub mod agent;
pub mod coordinator;
pub mod inbox;
pub mod realtime;
pub mod session;
pub mod watch;
pub mod wire;

pub use agent::{AgentOptions, fly};
pub use coordinator::{Options, coordinate, split};

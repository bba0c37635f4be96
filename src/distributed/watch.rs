//! Whether the coordinator is still there, as an agent process sees it:
//! its liveliness token, and for an agent it spawned, whether it is still
//! this process's parent. Shared by the lockstep link (`agent`) and the
//! agent's own clock (`realtime`).

use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::Subscriber;
use zenoh::sample::{Sample, SampleKind};

/// The start of a [`LinkError`](crate::pipelines::fleet::simulation::LinkError)'s
/// reason when the coordinator ended the run.
pub const ENDED: &str = "ended by the coordinator";

/// Whether the coordinator's liveliness token is there (or, for an agent it
/// spawned, whether it is still this process's parent).
pub struct Watch<'a> {
    subscriber: &'a Subscriber<FifoChannelHandler<Sample>>,
    parent: Option<u32>,
    seen: bool,
    gone: bool,
}

impl<'a> Watch<'a> {
    pub fn new(
        subscriber: &'a Subscriber<FifoChannelHandler<Sample>>,
        parent: Option<u32>,
    ) -> Self {
        Watch {
            subscriber,
            parent,
            seen: false,
            gone: false,
        }
    }

    /// The coordinator's token went away (after it was seen), or the
    /// coordinator that spawned this process is no longer its parent.
    pub fn gone(&mut self) -> bool {
        #[cfg(unix)]
        if self
            .parent
            .is_some_and(|p| std::os::unix::process::parent_id() != p)
        {
            self.gone = true;
        }
        while let Ok(Some(s)) = self.subscriber.try_recv() {
            match s.kind() {
                SampleKind::Put => self.seen = true,
                SampleKind::Delete => self.gone = true,
            }
        }
        self.gone
    }

    pub fn seen(&self) -> bool {
        self.seen
    }
}

//! The planners, and the one place they are registered.
//!
//! A pipeline is a plain function of a validated mission and a seed that
//! reports through an [`Observer`] and checks a [`CancelToken`]
//! (`interface.rs`); what a front end asks of it and of its outcome is its
//! face (`face.rs`, implemented in each pipeline's own `face.rs`). This file
//! registers them: each pipeline's module, its [`Kind`] and its
//! [`Outcome`], and the two matches that hand them their faces. Adding a
//! pipeline: see "Adding a pipeline" in `docs/architecture.md`.

pub mod chart;
pub mod face;
pub mod interface;
pub mod points;
pub mod quadrotor;
pub mod revision;
pub mod rows;
pub mod sketch;
pub mod table;
pub mod verify;

pub mod flatlo;
pub mod fleet;
pub mod theta_pso;

use serde::{Deserialize, Serialize};

pub use face::{
    Airframe, Ask, ExportRules, Header, Pipeline, PipelineOutcome, PlanOptions, Processes, Track,
    Verdict,
};
pub use interface::*;
pub use revision::{Prepared, Revision};

/// The planning pipelines: what `outcome::run` runs, what a track came
/// from, what the CLI's `--pipeline` and the designer's run keys name. Its
/// value on the command line and in the JSON is the `slug`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Kind {
    ThetaPso,
    Flatlo,
    Fleet,
}

/// A finished (or cancelled) run's result: the pipeline's own outcome.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Outcome {
    ThetaPso(Box<theta_pso::ThetaPsoOutcome>),
    Flatlo(Box<flatlo::FlatloOutcome>),
    Fleet(Box<fleet::FleetOutcome>),
}

/// What one run asks of its pipeline beyond the mission and the seed, in
/// the pipeline's own request type (θ-PSO: a plan to start warm from; the
/// fleet: agent processes to fly in). A front end builds the one it means
/// (`theta_pso::Request { .. }.into()`) or a pipeline's plain one
/// ([`Kind::request`]); the pipeline is the request's.
#[derive(Debug, Clone, PartialEq)]
pub enum Request {
    ThetaPso(theta_pso::Request),
    Flatlo(flatlo::Request),
    Fleet(fleet::Request),
}

impl Kind {
    /// Every pipeline, in the order menus and tables list them.
    pub const ALL: [Kind; 3] = [Kind::ThetaPso, Kind::Flatlo, Kind::Fleet];

    /// Its face: everything a front end asks of the pipeline.
    pub fn face(self) -> &'static dyn Pipeline {
        match self {
            Kind::ThetaPso => &theta_pso::face::ThetaPso,
            Kind::Flatlo => &flatlo::face::Flatlo,
            Kind::Fleet => &fleet::face::Fleet,
        }
    }
}

impl Kind {
    /// Its plain request: nothing asked beyond the mission and the seed.
    pub fn request(self) -> Request {
        match self {
            Kind::ThetaPso => theta_pso::Request::default().into(),
            Kind::Flatlo => flatlo::Request.into(),
            Kind::Fleet => fleet::Request::default().into(),
        }
    }
}

impl Request {
    /// The pipeline asked.
    pub fn kind(&self) -> Kind {
        match self {
            Request::ThetaPso(_) => Kind::ThetaPso,
            Request::Flatlo(_) => Kind::Flatlo,
            Request::Fleet(_) => Kind::Fleet,
        }
    }

    /// The agent processes it asks its vehicles to fly in, if any (the
    /// run path then goes through the transport).
    pub fn processes(&self) -> Option<Processes> {
        match self {
            Request::Fleet(r) => r.processes,
            Request::ThetaPso(_) | Request::Flatlo(_) => None,
        }
    }

    /// Its vehicles asked to fly in `processes` (a pipeline whose face
    /// [`Pipeline::flies_as_processes`]); `None` for one that cannot.
    pub fn in_processes(self, processes: Processes) -> Option<Request> {
        match self {
            Request::Fleet(_) => Some(
                fleet::Request {
                    processes: Some(processes),
                }
                .into(),
            ),
            Request::ThetaPso(_) | Request::Flatlo(_) => None,
        }
    }
}

impl From<theta_pso::Request> for Request {
    fn from(r: theta_pso::Request) -> Request {
        Request::ThetaPso(r)
    }
}

impl From<flatlo::Request> for Request {
    fn from(r: flatlo::Request) -> Request {
        Request::Flatlo(r)
    }
}

impl From<fleet::Request> for Request {
    fn from(r: fleet::Request) -> Request {
        Request::Fleet(r)
    }
}

impl Outcome {
    /// Its face: everything a front end asks of the outcome.
    pub fn face(&self) -> &dyn PipelineOutcome {
        match self {
            Outcome::ThetaPso(o) => o.as_ref(),
            Outcome::Flatlo(o) => o.as_ref(),
            Outcome::Fleet(o) => o.as_ref(),
        }
    }

    /// θ-PSO's own outcome, for what only it has (cost terms, IWPs).
    pub fn theta_pso(&self) -> Option<&theta_pso::ThetaPsoOutcome> {
        match self {
            Outcome::ThetaPso(o) => Some(o),
            _ => None,
        }
    }

    /// FLATLO's own outcome (the pair table, the manoeuvres).
    pub fn flatlo(&self) -> Option<&flatlo::FlatloOutcome> {
        match self {
            Outcome::Flatlo(o) => Some(o),
            _ => None,
        }
    }

    /// The fleet's own outcome (the distance series, the network).
    pub fn fleet(&self) -> Option<&fleet::FleetOutcome> {
        match self {
            Outcome::Fleet(o) => Some(o),
            _ => None,
        }
    }
}

impl From<theta_pso::ThetaPsoOutcome> for Outcome {
    fn from(o: theta_pso::ThetaPsoOutcome) -> Outcome {
        Outcome::ThetaPso(Box::new(o))
    }
}

impl From<flatlo::FlatloOutcome> for Outcome {
    fn from(o: flatlo::FlatloOutcome) -> Outcome {
        Outcome::Flatlo(Box::new(o))
    }
}

impl From<fleet::FleetOutcome> for Outcome {
    fn from(o: fleet::FleetOutcome) -> Outcome {
        Outcome::Fleet(Box::new(o))
    }
}

/// The pipeline a front end starts with when nothing else is chosen (the
/// designer's live planning, a recording that names none): θ-PSO.
impl Default for Kind {
    fn default() -> Kind {
        Kind::ThetaPso
    }
}

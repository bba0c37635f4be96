//! Missions: the TOML model, loading with located diagnostics, validation and
//! atomic saving. Everything downstream takes a `Mission` that passed `validate`.

mod builtin;
mod diagnostic;
mod edit;
mod file;
pub mod geodesy;
pub mod geodetic;
mod model;
mod presets;
mod source;
mod validate;

pub use builtin::{BUILTIN, Builtin, default_mission};
pub use diagnostic::{Diagnostic, Report, Severity};
pub use edit::edit_in_place;
pub use file::{
    Checked, Loaded, MissionError, check_str, load, parse_str, read, save, save_edited,
    to_toml_string, write_atomically,
};
pub use model::*;
pub use presets::Preset;
pub use source::{FieldPath, LineCol, PathSegment, SourceMap};
pub use validate::{compact, compact_digits, validate};

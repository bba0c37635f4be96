//! Missions: the TOML model, loading with located diagnostics, validation and
//! atomic saving. Everything downstream takes a `Mission` that passed `validate`.

mod builtin;
mod diagnostic;
mod edit;
mod file;
pub mod geodesy;
pub mod geodetic;
mod model;
mod obstacle;
mod presets;
mod read;
mod source;
mod template;
mod validate;

pub use builtin::{BUILTIN, Builtin, default_mission};
pub use diagnostic::{Diagnostic, Report, Severity};
pub use edit::edit_in_place;
pub use file::{
    Checked, Loaded, MissionError, check_str, load, parse_str, read, save, save_edited,
    to_toml_string,
};
pub use model::*;
pub use obstacle::*;
pub use presets::{
    Preset, max_pair_distance, min_pair_distance, rescale, reshape, resize_custom, round_mm,
    smallest_scale, spacing_of,
};
pub use source::{FieldPath, LineCol, PathSegment, SourceMap};
pub use template::{name_for, template, template_text};
pub use validate::{
    Checker, MAX_FLIGHTS, SECTION_RULES, SectionRules, compact, compact_digits, physical, validate,
};

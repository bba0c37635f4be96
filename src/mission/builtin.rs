//! The missions shipped in `missions/`, compiled into the binary so skyform
//! works from any directory.

use super::file::{Loaded, parse_str};

/// A shipped mission: its file name and text.
#[derive(Debug, Clone, Copy)]
pub struct Builtin {
    pub file_name: &'static str,
    pub text: &'static str,
}

/// Every shipped mission; the first is the default.
pub const BUILTIN: &[Builtin] = &[
    Builtin {
        file_name: "bridge-inspection.toml",
        text: include_str!("../../missions/bridge-inspection.toml"),
    },
    Builtin {
        file_name: "narrow-passage.toml",
        text: include_str!("../../missions/narrow-passage.toml"),
    },
    Builtin {
        file_name: "flatlo-squadron.toml",
        text: include_str!("../../missions/flatlo-squadron.toml"),
    },
    Builtin {
        file_name: "fleet-triangle.toml",
        text: include_str!("../../missions/fleet-triangle.toml"),
    },
];

/// The mission the TUI opens with no file: the θ-PSO paper's bridge.
pub fn default_mission() -> Loaded {
    let builtin = BUILTIN[0];
    // The shipped files are validated by the test suite, so this cannot fail
    // in a released binary; a broken edit of the file fails the tests first.
    parse_str(builtin.text, builtin.file_name)
        .unwrap_or_else(|e| panic!("built-in mission {} is invalid: {e}", builtin.file_name))
}

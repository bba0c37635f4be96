//! The minimal mission a new file starts from: a box, a start and a goal,
//! the default formation, nothing else (no origin, no obstacles, no comment
//! about any other mission). A shipped mission is copied only on purpose
//! (`skyform new FILE --from …`, or opening it in the designer).

use super::file::{MissionError, parse_str};
use super::model::Mission;

/// The text of a new mission called `name`.
pub fn template_text(name: &str) -> String {
    let name = toml_edit::Value::from(name).to_string();
    format!(
        r#"# A skyform mission (every key and its default: README.md, "Format").
# Exports to autopilots (.plan, .waypoints) need an [origin]: the WGS-84
# latitude, longitude and altitude of x = y = 0 (Mission in the designer).
name = {name}
seed = 1

[bounds]  # the operating box: x east and y north, metres; z the altitude band
x = [0.0, 100.0]
y = [0.0, 100.0]
z = [5.0, 20.0]

[route]  # where the formation's centroid starts and ends (x, y, z), metres
start = [10.0, 50.0, 10.0]
goal = [90.0, 50.0, 10.0]
"#
    )
}

/// The mission of [`template_text`], read as any file is.
pub fn template(name: &str) -> Result<Mission, MissionError> {
    parse_str(&template_text(name), "(new mission)").map(|l| l.mission)
}

/// The name a new mission at `path` gets: its file's stem.
pub fn name_for(path: &std::path::Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| !s.trim().is_empty())
        .unwrap_or_else(|| "new mission".to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 24, item 1: a new mission is minimal and valid, without a
    /// warning: no origin, no obstacles, the default formation, one start
    /// and one goal, no word of the bridge.
    #[test]
    fn the_template_is_minimal_and_valid() {
        let text = template_text("turbines \"north\"");
        let loaded = parse_str(&text, "new.toml").unwrap();
        assert_eq!(loaded.warnings.diagnostics, []);
        let m = loaded.mission;
        assert_eq!(m.name, "turbines \"north\"");
        assert!(m.origin.is_none());
        assert!(m.obstacles.is_empty());
        assert!(m.reconfiguration.waypoints.is_empty());
        assert_eq!(m.formation, crate::mission::Formation::default());
        assert!(crate::outcome::diagnose::diagnose(&m).is_empty());
        for word in ["bridge", "pier", "Sydney", "triangle", "eq."] {
            assert!(!text.contains(word), "{word} in\n{text}");
        }
    }
}

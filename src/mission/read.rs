//! A file's text into the typed mission, with every error located: what
//! loading (`file.rs`) and saving in place (`edit.rs`) both read with.

use serde::Deserialize;
use toml::de::DeTable;

use super::diagnostic::Diagnostic;
use super::geodetic::{self, Forms};
use super::model::Mission;
use super::source::SourceMap;

/// The typed mission of a file's text, its latitude/longitude positions
/// converted to ENU (`geodetic.rs`), not validated; and the forms the file
/// wrote its positions in (a save writes them back so). Fails on the first
/// type error, or on every position that cannot be converted.
pub(super) fn read_model(
    text: &str,
    source: &SourceMap<'_>,
) -> Result<(Mission, Forms), Vec<Diagnostic>> {
    let root = DeTable::parse(text).map_err(|e| vec![locate_toml_error(&e, source)])?;
    let conversions = geodetic::convert(&root)?;
    let root = geodetic::apply(root, &conversions);
    let mut mission = Mission::deserialize(toml::de::Deserializer::from(root))
        .map_err(|e| vec![locate_toml_error(&e, source)])?;
    for o in &mut mission.obstacles {
        o.settle();
    }
    Ok((mission, conversions.forms))
}

/// A toml error as a diagnostic on the field under its span.
pub(super) fn locate_toml_error(e: &toml::de::Error, source: &SourceMap<'_>) -> Diagnostic {
    let path = e
        .span()
        .map(|span| source.path_at(span.start))
        .unwrap_or_default();
    let mut d = Diagnostic::error(path, e.message().trim().to_owned());
    d.location = e.span().map(|span| source.line_col(span.start));
    d
}

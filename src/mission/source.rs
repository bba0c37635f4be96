//! Where things are in a mission file: field paths ↔ byte spans ↔ line:column.
//!
//! Serde gives us a typed `Mission` but forgets positions; validation works on
//! the typed value. This index re-reads the same text with toml's spanned
//! parser so each problem found on the typed value can point at its line.

use std::fmt;
use std::ops::Range;

use serde::Serialize;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// One step of a field path: a table key or an array index.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(untagged)]
pub enum PathSegment {
    Key(String),
    Index(usize),
}

/// A path to a field of the mission, printed as `obstacles[3].radius`.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct FieldPath(pub Vec<PathSegment>);

impl FieldPath {
    pub fn root() -> Self {
        FieldPath(Vec::new())
    }

    /// This path extended by a key.
    pub fn key(&self, key: &str) -> Self {
        let mut segments = self.0.clone();
        segments.push(PathSegment::Key(key.to_owned()));
        FieldPath(segments)
    }

    /// This path extended by an array index.
    pub fn index(&self, index: usize) -> Self {
        let mut segments = self.0.clone();
        segments.push(PathSegment::Index(index));
        FieldPath(segments)
    }

    pub fn is_root(&self) -> bool {
        self.0.is_empty()
    }

    /// Whether this path is `ancestor` or lies below it: `obstacles[3].radius`
    /// starts with `obstacles[3]` and with itself, not with `obstacles[3].r`
    /// or `obstacles[30]` (it compares segments, not text).
    pub fn starts_with(&self, ancestor: &FieldPath) -> bool {
        self.0.starts_with(&ancestor.0)
    }
}

impl fmt::Display for FieldPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, segment) in self.0.iter().enumerate() {
            match segment {
                PathSegment::Key(key) if i == 0 => write!(f, "{key}")?,
                PathSegment::Key(key) => write!(f, ".{key}")?,
                PathSegment::Index(index) => write!(f, "[{index}]")?,
            }
        }
        Ok(())
    }
}

impl Serialize for FieldPath {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

/// A 1-based line and column in a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct LineCol {
    pub line: usize,
    pub column: usize,
}

impl fmt::Display for LineCol {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.line, self.column)
    }
}

/// The text of a mission file with its spanned syntax tree.
pub struct SourceMap<'a> {
    text: &'a str,
    root: Option<Spanned<DeTable<'a>>>,
}

impl<'a> SourceMap<'a> {
    /// Indexes `text`. Text that does not parse gives a map without positions.
    pub fn new(text: &'a str) -> Self {
        SourceMap {
            text,
            root: DeTable::parse(text).ok(),
        }
    }

    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, offset: usize) -> LineCol {
        let offset = offset.min(self.text.len());
        let before = self.text.get(..offset).unwrap_or(self.text);
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let column = before.get(line_start..).map_or(0, |s| s.chars().count()) + 1;
        LineCol { line, column }
    }

    /// Where `path` is written: the key of a field, the element of an array.
    /// A field that is not in the file (it took its default) resolves to the
    /// closest enclosing table that is.
    pub fn locate(&self, path: &FieldPath) -> Option<LineCol> {
        self.span_of(path).map(|span| self.line_col(span.start))
    }

    fn span_of(&self, path: &FieldPath) -> Option<Range<usize>> {
        let root = self.root.as_ref()?;
        let mut best: Option<Range<usize>> = None;
        let mut table: Option<&DeTable> = Some(root.get_ref());
        let mut array: Option<&[Spanned<DeValue>]> = None;
        for segment in &path.0 {
            let value = match (segment, table, array) {
                (PathSegment::Key(key), Some(t), _) => {
                    let Some((k, v)) = t.iter().find(|(k, _)| k.get_ref() == key) else {
                        break;
                    };
                    best = Some(k.span());
                    v
                }
                (PathSegment::Index(i), _, Some(items)) => {
                    let Some(v) = items.get(*i) else { break };
                    best = Some(v.span());
                    v
                }
                _ => break,
            };
            (table, array) = match value.get_ref() {
                DeValue::Table(t) => (Some(t), None),
                DeValue::Array(a) => (None, Some(a.as_ref())),
                _ => (None, None),
            };
        }
        best
    }

    /// The deepest field whose key or value contains the byte `offset`
    /// (used to name the field of a parser error that only has a span).
    pub fn path_at(&self, offset: usize) -> FieldPath {
        let mut segments = Vec::new();
        if let Some(root) = self.root.as_ref() {
            find_in_table(root.get_ref(), offset, &mut segments);
        }
        segments.reverse();
        FieldPath(segments)
    }
}

/// Searches the children (not the table's own span: toml gives an array of
/// tables a span that does not cover its later tables). Pushes the path in
/// reverse, deepest segment first.
fn find_in_table(table: &DeTable<'_>, offset: usize, out: &mut Vec<PathSegment>) -> bool {
    for (key, value) in table.iter() {
        if contains(&key.span(), offset) || find_in_value(value, offset, out) {
            out.push(PathSegment::Key(key.get_ref().to_string()));
            return true;
        }
    }
    false
}

fn find_in_value(value: &Spanned<DeValue<'_>>, offset: usize, out: &mut Vec<PathSegment>) -> bool {
    match value.get_ref() {
        DeValue::Table(t) => find_in_table(t, offset, out) || contains(&value.span(), offset),
        DeValue::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                if find_in_value(item, offset, out) {
                    out.push(PathSegment::Index(i));
                    return true;
                }
            }
            contains(&value.span(), offset)
        }
        _ => contains(&value.span(), offset),
    }
}

fn contains(span: &Range<usize>, offset: usize) -> bool {
    span.start <= offset && offset < span.end.max(span.start + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "name = \"x\"\n\n[bounds]\nx = [0.0, 1.0]\n\n[[obstacles]]\nname = \"a\"\n\n[[obstacles]]\nname = \"b\"\nradius = 2.0\n";

    #[test]
    fn field_paths_print_like_toml_accessors() {
        let path = FieldPath::root().key("obstacles").index(3).key("radius");
        assert_eq!(path.to_string(), "obstacles[3].radius");
    }

    #[test]
    fn a_path_starts_with_itself_and_its_parents_only() {
        let o = |i| FieldPath::root().key("obstacles").index(i);
        let radius = o(3).key("radius");
        assert!(radius.starts_with(&radius) && radius.starts_with(&o(3)));
        assert!(radius.starts_with(&FieldPath::root()));
        assert!(!radius.starts_with(&o(30)) && !o(30).starts_with(&o(3)));
        assert!(!radius.starts_with(&o(3).key("r")));
        assert!(!o(3).starts_with(&radius));
    }

    #[test]
    fn locates_keys_inside_arrays_of_tables() {
        let map = SourceMap::new(TEXT);
        let path = FieldPath::root().key("obstacles").index(1).key("radius");
        assert_eq!(
            map.locate(&path),
            Some(LineCol {
                line: 11,
                column: 1
            })
        );
        let x = FieldPath::root().key("bounds").key("x");
        assert_eq!(map.locate(&x), Some(LineCol { line: 4, column: 1 }));
    }

    #[test]
    fn a_missing_field_falls_back_to_its_table() {
        let map = SourceMap::new(TEXT);
        let path = FieldPath::root().key("obstacles").index(0).key("radius");
        assert_eq!(map.locate(&path).map(|lc| lc.line), Some(6));
    }

    #[test]
    fn path_at_names_the_field_under_an_offset() {
        let map = SourceMap::new(TEXT);
        let offset = TEXT.find("2.0").unwrap_or_default();
        assert_eq!(map.path_at(offset).to_string(), "obstacles[1].radius");
    }
}

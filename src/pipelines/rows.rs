//! A pipeline's section as the designer's inspector shows it: one row a
//! field, as data (a name, a unit, its keys in the section, its value read
//! and written as text). A pipeline lists its section's rows on its face
//! (`Pipeline::rows`, kept in its `section.rs`); the inspector shows the
//! rows of the selected section and names no pipeline. Also the words every
//! row reads and writes a value in, which the inspector's own tables share.

use nalgebra::Point2;

use crate::mission::Mission;
use crate::mission::geodesy::Frame;

/// One field of a pipeline's section.
pub struct Row {
    pub name: &'static str,
    /// Shown after the name, in parentheses; empty for none.
    pub unit: &'static str,
    /// Keys below the section: where the field is. Rows that share their
    /// keys are that array's elements, in order (`start` x, y).
    pub keys: &'static [&'static str],
    /// The value as it would be typed.
    pub get: fn(&Mission) -> Option<String>,
    /// Writes the (trimmed) text, parsed; the error says what is expected.
    pub set: fn(&mut Mission, &str) -> Result<(), String>,
}

/// One field of a point of a pipeline's section (`PointKind::rows`: a
/// fleet target's time, place, latitude): as a [`Row`], of the point at an
/// index of its list.
pub struct PointRow {
    pub name: &'static str,
    pub unit: &'static str,
    /// Keys below the point's table in the list.
    pub keys: &'static [&'static str],
    /// The value of point `i`; `None` for a row the point does not have.
    pub get: fn(&Mission, usize) -> Option<String>,
    pub set: fn(&mut Mission, usize, &str) -> Result<(), String>,
}

/// Degrees to 8 decimals (about a millimetre), as typed.
pub fn degrees(v: f64) -> String {
    let s = format!("{v:.8}");
    s.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// The latitude (or longitude) of ground point `p` through the mission's
/// `[origin]` (the geodesy of the files and exports), as typed; empty for
/// a mission without an origin.
pub fn geo_text(m: &Mission, p: Point2<f64>, latitude: bool) -> String {
    m.origin.as_ref().map_or_else(String::new, |o| {
        let g = Frame::new(o).ground_to_geodetic(&p);
        degrees(if latitude { g.latitude } else { g.longitude })
    })
}

/// Where ground point `here` goes when its latitude (or longitude) is typed
/// as `text`, the other kept. The value shown, applied again, moves nothing.
pub fn geo_moved(
    m: &Mission,
    here: Point2<f64>,
    text: &str,
    latitude: bool,
) -> Result<Point2<f64>, String> {
    let Some(origin) = &m.origin else {
        return Err(
            "a latitude/longitude needs the mission's [origin] (Mission: origin lat, lon)".into(),
        );
    };
    let frame = Frame::new(origin);
    let g = frame.ground_to_geodetic(&here);
    if text == degrees(if latitude { g.latitude } else { g.longitude }) {
        return Ok(here);
    }
    let v = number(text)?;
    let limit = if latitude { 90.0 } else { 180.0 };
    if v.abs() > limit {
        return Err(format!("must be within ±{limit}°, got {v}"));
    }
    let (la, lo) = if latitude {
        (v, g.longitude)
    } else {
        (g.latitude, v)
    };
    Ok(frame.ground_to_enu(la, lo))
}

/// Metres, degrees, gains: any finite number.
pub fn number(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        // `1e400` is a number, one too large for any field (Rust reads it
        // as infinity); `inf` and `nan` are not numbers a field takes.
        Ok(v) if v.is_infinite() && text.chars().any(|c| c.is_ascii_digit()) => Err(format!(
            "'{text}' is too large: the largest number a field holds is about 1.8e308"
        )),
        _ => Err(format!("'{text}' is not a number")),
    }
}

/// Formats a number the way it would be typed: exactly when that is short
/// (so opening a field and applying it changes nothing), else to 4 decimals.
pub fn fmt_num(v: f64) -> String {
    // Huge and tiny values in scientific notation: `1e300`, not 301 digits
    // (it reads back as typed).
    if v.is_finite() && v != 0.0 && !(1e-4..1e9).contains(&v.abs()) {
        return format!("{v:e}");
    }
    let exact = format!("{v}");
    let s = if exact.len() <= 12 {
        exact
    } else {
        let rounded = format!("{v:.4}");
        rounded
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_owned()
    };
    if s == "-0" { "0".into() } else { s }
}

/// A whole number ≥ 0: a count.
pub fn count(text: &str) -> Result<usize, String> {
    text.parse::<usize>()
        .map_err(|_| format!("'{text}' is not a whole number ≥ 0"))
}

/// Nothing (or `auto`) for none, else a number.
pub fn auto_or_number(text: &str) -> Result<Option<f64>, String> {
    let t = text.trim();
    if t.is_empty() || t.eq_ignore_ascii_case("auto") {
        Ok(None)
    } else {
        number(t).map(Some).map_err(|e| format!("{e}, or auto"))
    }
}

/// Writes a parsed value (or passes its error on).
pub fn put<T>(place: &mut T, value: Result<T, String>) -> Result<(), String> {
    *place = value?;
    Ok(())
}

/// A value shown as it is printed.
pub fn text(value: impl ToString) -> Option<String> {
    Some(value.to_string())
}

/// A number shown as it would be typed ([`fmt_num`]).
pub fn num(value: f64) -> Option<String> {
    Some(fmt_num(value))
}

/// A list the file holds, as a count (or what its absence means).
pub fn listed(n: usize, what: &str, none: &str) -> String {
    if n == 0 {
        format!("none: {none}")
    } else {
        format!("{n} {what} (edit them in the file)")
    }
}

/// The write of a value shown but edited in the file.
pub fn in_the_file(_: &mut Mission, _: &str) -> Result<(), String> {
    Err("a list of the file: edit it there (the inspector shows its messages)".into())
}

#[cfg(test)]
mod tests {
    use crate::pipelines::Kind;

    /// Every pipeline's rows, read through its face: each shows a value on
    /// the bundled mission, writing back the value shown changes nothing,
    /// (a list edited in the file says so), and a value that is not one is
    /// refused, the mission left as it was.
    #[test]
    fn every_sections_rows_show_a_value_and_write_it_back_unchanged() {
        let m = crate::mission::default_mission().mission;
        let mut rows = 0;
        for kind in Kind::ALL {
            let key = kind.words().section.0;
            for row in kind.face().rows() {
                rows += 1;
                let shown = (row.get)(&m).unwrap_or_else(|| panic!("{key}: {}", row.name));
                let mut again = m.clone();
                // A list edited in the file says so; every other row takes
                // the value it shows.
                match (row.set)(&mut again, &shown) {
                    Err(e) if e.contains("edit it there") => {}
                    other => assert_eq!(other, Ok(()), "{key}: {} = {shown}", row.name),
                }
                assert_eq!(again, m, "{key}: {} = {shown}", row.name);
                assert!((row.set)(&mut again, "x!").is_err(), "{}", row.name);
                assert_eq!(again, m, "{key}: {} refused, yet changed", row.name);
            }
        }
        assert!(rows > 70, "{rows}");
    }

    /// Every point's rows (`PointKind::rows`), on every shipped mission's
    /// points: the same, of the point at its index; and a row the point
    /// does not have (a target of one point per agent has no `x`) shows
    /// nothing.
    #[test]
    fn every_points_rows_show_a_value_and_write_it_back_unchanged() {
        let mut shown = 0;
        for builtin in crate::mission::BUILTIN {
            let m = crate::mission::parse_str(builtin.text, builtin.file_name)
                .unwrap_or_else(|e| panic!("{e}"))
                .mission;
            for point in crate::pipelines::points::every_point(&m) {
                let kind = point.kind().unwrap_or_else(|| panic!("{point:?}"));
                for row in kind.rows {
                    let Some(value) = (row.get)(&m, point.index) else {
                        continue;
                    };
                    shown += 1;
                    let mut again = m.clone();
                    match (row.set)(&mut again, point.index, &value) {
                        Err(e) if e.contains("in the file") => {}
                        other => assert_eq!(other, Ok(()), "{}: {}", builtin.file_name, row.name),
                    }
                    assert_eq!(again, m, "{}: {} = {value}", builtin.file_name, row.name);
                }
                assert!((kind.rows[0].get)(&m, usize::MAX).is_none());
            }
        }
        assert!(shown >= 4, "{shown}");
    }
}

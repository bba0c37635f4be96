//! Unusable IWPs grouped for a reader: a 200-tree forest has dozens, each
//! with the same few reasons. Grouped by reason (the names and widths of
//! each taken out), counted, the few nearest the route named; the IWP
//! table and the inspector list every one. The run's log, the CLI summary
//! and the designer's jobs panel all group them here.

use nalgebra::{Point2, Point3};

use super::Iwp;
use crate::base::geometry::segment_point_distance;

/// Unusable IWPs that share a reason.
#[derive(Debug, Clone, PartialEq)]
pub struct UnusableGroup {
    /// The reason without the figures of any one IWP; the obstacles it
    /// names, by name (those of the IWPs nearest the route first).
    pub reason: String,
    pub count: usize,
    /// The IWPs of the group nearest the route, nearest first (at most the
    /// number asked for).
    pub nearest: Vec<[String; 2]>,
}

/// An IWP of a group: its distance to the route, the obstacles it is
/// between, the names its reason quotes and the figures it gives.
type Member = (f64, [String; 2], Vec<String>, Vec<f64>);

/// The enabled, unusable IWPs of `iwps` grouped by reason, the largest
/// group first, each naming its `named` IWPs nearest `route` (x-y).
pub fn unusable_groups(iwps: &[Iwp], route: &[Point3<f64>], named: usize) -> Vec<UnusableGroup> {
    let mut groups: Vec<(String, Vec<Member>)> = Vec::new();
    for iwp in iwps.iter().filter(|i| i.enabled) {
        let Some(reason) = &iwp.unusable else {
            continue;
        };
        let key = reason_kind(reason);
        let entry = (
            distance_to(route, &iwp.position),
            iwp.between.clone(),
            quoted(reason),
            figures(reason),
        );
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, members)) => members.push(entry),
            None => groups.push((key, vec![entry])),
        }
    }
    let mut out: Vec<UnusableGroup> = groups
        .into_iter()
        .map(|(kind, mut members)| {
            members.sort_by(|a, b| a.0.total_cmp(&b.0));
            UnusableGroup {
                reason: with_names(&kind, &members),
                count: members.len(),
                nearest: members
                    .into_iter()
                    .take(named)
                    .map(|(_, b, ..)| b)
                    .collect(),
            }
        })
        .collect();
    out.sort_by_key(|g| std::cmp::Reverse(g.count));
    out
}

/// A reason with what is particular to one IWP taken out: the part before
/// a colon, quoted names as `'…'`, numbers as `#`.
fn reason_kind(reason: &str) -> String {
    let head = reason.split(':').next().unwrap_or(reason);
    let mut out = String::new();
    let mut quoted = false;
    let mut in_number = false;
    for c in head.chars() {
        if c == '\'' {
            quoted = !quoted;
            if quoted {
                out.push_str("'…'");
            }
            continue;
        }
        if quoted {
            continue;
        }
        let digit = c.is_ascii_digit() || (in_number && c == '.');
        if digit {
            if !in_number {
                out.push('#');
            }
            in_number = true;
            continue;
        }
        in_number = false;
        out.push(c);
    }
    out.trim().to_owned()
}

/// The names `reason` quotes before its colon, in order.
fn quoted(reason: &str) -> Vec<String> {
    let head = reason.split(':').next().unwrap_or(reason);
    head.split('\'')
        .skip(1)
        .step_by(2)
        .map(str::to_owned)
        .collect()
}

/// The figures `reason` gives before its colon, in order (outside quotes).
fn figures(reason: &str) -> Vec<f64> {
    let head = reason.split(':').next().unwrap_or(reason);
    let mut out = Vec::new();
    for (k, piece) in head.split('\'').enumerate() {
        if k % 2 == 1 {
            continue;
        }
        let mut number = String::new();
        for c in piece.chars().chain(std::iter::once(' ')) {
            if c.is_ascii_digit() || (!number.is_empty() && c == '.') {
                number.push(c);
            } else if !number.is_empty() {
                out.push(number.trim_end_matches('.').parse().unwrap_or(f64::NAN));
                number.clear();
            }
        }
    }
    out
}

/// The `slot`-th figure over a group: the one value, or the range.
fn figure_range(members: &[Member], slot: usize) -> String {
    let values: Vec<f64> = members
        .iter()
        .filter_map(|m| m.3.get(slot).copied())
        .filter(|v| v.is_finite())
        .collect();
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if values.is_empty() {
        "#".to_owned()
    } else if hi - lo < 1e-9 {
        format!("{}", (lo * 100.0).round() / 100.0)
    } else {
        format!(
            "{}-{}",
            (lo * 100.0).round() / 100.0,
            (hi * 100.0).round() / 100.0
        )
    }
}

/// A group's reason (`kind`, its quoted names taken out as `'…'`, its
/// figures as `#`) with the names put back, at each place the one name
/// every member quotes there, else the one of the IWP nearest the route and
/// how many others ("'post 4c' or 3 others"), never a literal `'…'`; and
/// each figure as the group's one value or its range ("1.5-2.1").
fn with_names(kind: &str, members: &[Member]) -> String {
    let mut figure = 0;
    let kind: String = kind
        .split('#')
        .enumerate()
        .map(|(k, piece)| {
            if k == 0 {
                piece.to_owned()
            } else {
                figure += 1;
                format!("{}{piece}", figure_range(members, figure - 1))
            }
        })
        .collect();
    let kind = kind.as_str();
    let mut out = String::new();
    for (slot, piece) in kind.split("'…'").enumerate() {
        if slot > 0 {
            let mut names: Vec<&str> = Vec::new();
            for (_, _, quoted, _) in members {
                if let Some(name) = quoted.get(slot - 1)
                    && !names.contains(&name.as_str())
                {
                    names.push(name);
                }
            }
            out.push_str(&match names.as_slice() {
                [] => "an obstacle".to_owned(),
                [one] => format!("'{one}'"),
                [nearest, other] => format!("'{nearest}' or '{other}'"),
                [nearest, others @ ..] => format!("'{nearest}' or {} others", others.len()),
            });
        }
        out.push_str(piece);
    }
    out
}

/// The x-y distance from `p` to the polyline `route` (∞ without one).
pub fn distance_to(route: &[Point3<f64>], p: &Point2<f64>) -> f64 {
    match route {
        [] => f64::INFINITY,
        [only] => (only.xy() - p).norm(),
        _ => route
            .windows(2)
            .map(|w| segment_point_distance(&w[0].xy(), &w[1].xy(), p))
            .fold(f64::INFINITY, f64::min),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mission::ShapeChoice;
    use crate::pipelines::theta_pso::Iwp;
    use nalgebra::Vector2;

    fn iwp(a: &str, b: &str, y: f64, reason: Option<&str>) -> Iwp {
        Iwp {
            between: [a.into(), b.into()],
            obstacles: [0, 1],
            position: Point2::new(50.0, y),
            gap: 1.0,
            normal: Vector2::x(),
            enabled: true,
            choice: ShapeChoice::Auto,
            shape: None,
            unusable: reason.map(str::to_owned),
            hold: 0.0,
            straight: 0.0,
            window: [f64::NEG_INFINITY, f64::INFINITY],
            gate: None,
        }
    }

    /// Issue 23, item 4 (the designer half): forty unusable IWPs read as
    /// two lines: a count by reason, the nearest named.
    #[test]
    fn unusable_iwps_are_counted_by_reason_and_the_nearest_named() {
        let mut iwps = Vec::new();
        for k in 0..30 {
            let why = format!(
                "no shape fits: the narrowest, a column, is 1.{k:02} m wide and the gap is 0.9 m"
            );
            iwps.push(iwp(
                &format!("tree {k}"),
                &format!("tree {}", k + 1),
                k as f64,
                Some(&why),
            ));
        }
        for k in 0..10 {
            let why =
                format!("held through the gap, the alignment would pass within r_Q of 'post {k}'");
            iwps.push(iwp(
                &format!("post {k}"),
                "wall",
                40.0 + k as f64,
                Some(&why),
            ));
        }
        iwps.push(iwp("gate a", "gate b", 5.0, None));
        let why = "held through the gap, the shrink would pass within r_Q of 'mast'";
        iwps.push(iwp("mast", "wall", 60.0, Some(why)));
        iwps.push(iwp("mast", "fence", 61.0, Some(why)));
        let route = [Point3::new(0.0, 12.0, 10.0), Point3::new(100.0, 12.0, 10.0)];
        let groups = unusable_groups(&iwps, &route, 3);
        assert_eq!(groups.len(), 3, "{groups:?}");
        assert_eq!(groups[0].reason, "no shape fits");
        // The figures as the group's range (issue 37).
        let mut rows = Vec::new();
        for k in 0..4 {
            let why = format!(
                "rotation leaves the formation 4.47 m wide and the gap is 1.{} m",
                k + 2
            );
            rows.push(iwp(
                &format!("p {k}"),
                &format!("p {}", k + 1),
                0.0,
                Some(&why),
            ));
        }
        let one = unusable_groups(&rows, &route, 1);
        assert_eq!(
            one[0].reason,
            "rotation leaves the formation 4.47 m wide and the gap is 1.2-1.5 m"
        );
        assert_eq!(groups[0].count, 30);
        let nearest: Vec<&str> = groups[0].nearest.iter().map(|b| b[0].as_str()).collect();
        assert_eq!(nearest, ["tree 12", "tree 11", "tree 13"]);
        // The names of the obstacles in the way, not '…' (issue 36): the
        // one nearest the route, and how many more.
        assert_eq!(
            groups[1].reason,
            "held through the gap, the alignment would pass within r_Q of 'post 0' or 9 others"
        );
        assert_eq!(groups[1].count, 10);
        // One name throughout the group: that name.
        assert_eq!(
            groups[2].reason,
            "held through the gap, the shrink would pass within r_Q of 'mast'"
        );
    }
}

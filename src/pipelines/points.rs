//! The points of a pipeline's own mission section that the designer draws
//! on the map and lets the operator pick, move, add and delete (the fleet's
//! targets). Each pipeline lists its kinds on its face
//! ([`super::Pipeline::points`]), as data; the map, the mouse, the editor
//! and the item list loop over them and name no pipeline.

use nalgebra::Point2;

use super::Kind;
use crate::mission::Mission;

/// One kind of editable point, as data: its words and what the designer
/// may do with one.
pub struct PointKind {
    /// One of them, in an item's title: `Fleet target` (numbered from 1 after it).
    pub noun: &'static str,
    /// What the map draws at its centre, before its number: `◎`.
    pub glyph: &'static str,
    /// Where the list is in the mission file (an array of tables):
    /// `["fleet", "targets"]`.
    pub path: [&'static str; 2],
    /// How many `mission` has.
    pub count: fn(&Mission) -> usize,
    /// Where point `i` is on the map (its centre), if it exists.
    pub centre: fn(&Mission, usize) -> Option<Point2<f64>>,
    /// The spots point `i` marks besides its centre (a target of one point
    /// per agent: each of them), drawn as dots.
    pub spots: fn(&Mission, usize) -> Vec<Point2<f64>>,
    /// Moves point `i` so its centre is at `p` (every spot with it).
    pub move_to: fn(&mut Mission, usize, Point2<f64>),
    /// Adds a new one after the last (the designer's `d`), where the
    /// mission suggests.
    pub add: fn(&mut Mission),
    /// Deletes point `i`, if it exists.
    pub remove: fn(&mut Mission, usize),
    /// Its fields, as the designer's inspector shows and edits them.
    pub rows: &'static [super::rows::PointRow],
}

/// One point of one kind: the pipeline, its kind's index on the face, the
/// point's index in the mission's list.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PointRef {
    pub pipeline: Kind,
    pub kind: usize,
    pub index: usize,
}

impl PointRef {
    /// Its kind's words and actions; `None` for a kind its face does not
    /// list (never made by [`every_point`]).
    pub fn kind(&self) -> Option<&'static PointKind> {
        self.pipeline.face().points().get(self.kind)
    }

    /// `Fleet target 2`.
    pub fn title(&self) -> String {
        let noun = self.kind().map_or("Point", |k| k.noun);
        format!("{noun} {}", self.index + 1)
    }

    /// It is still in `mission` (after an undo, say).
    pub fn exists(&self, mission: &Mission) -> bool {
        self.kind().is_some_and(|k| self.index < (k.count)(mission))
    }

    /// Where it is on the map.
    pub fn centre(&self, mission: &Mission) -> Option<Point2<f64>> {
        self.kind().and_then(|k| (k.centre)(mission, self.index))
    }
}

/// Every kind `pipeline` lets the designer edit, each with its index.
pub fn kinds_of(pipeline: Kind) -> impl Iterator<Item = (usize, &'static PointKind)> {
    pipeline.face().points().iter().enumerate()
}

/// Every editable point of `mission`, pipeline by pipeline, kind by kind.
pub fn every_point(mission: &Mission) -> Vec<PointRef> {
    Kind::ALL
        .into_iter()
        .flat_map(|pipeline| points_of(mission, pipeline))
        .collect()
}

/// `pipeline`'s editable points in `mission`, kind by kind.
pub fn points_of(mission: &Mission, pipeline: Kind) -> Vec<PointRef> {
    kinds_of(pipeline)
        .flat_map(|(kind, k)| {
            (0..(k.count)(mission)).map(move |index| PointRef {
                pipeline,
                kind,
                index,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mission::FleetTarget;

    /// The fleet's targets are its points: listed in order, moved, added
    /// after the last and deleted through its face alone.
    #[test]
    fn the_fleets_targets_are_edited_through_its_face() {
        let mut m = crate::mission::default_mission().mission;
        m.fleet.targets = vec![
            FleetTarget::around(0.0, Point2::new(10.0, 5.0)),
            FleetTarget::around(20.0, Point2::new(-4.0, 2.0)),
        ];
        let points = every_point(&m);
        assert_eq!(points.len(), 2);
        assert!(points.iter().all(|p| p.pipeline == Kind::Fleet));
        assert_eq!(points[1].title(), "Fleet target 2");
        assert_eq!(points[1].centre(&m), Some(Point2::new(-4.0, 2.0)));

        let kind = points[0].kind().expect("the fleet lists its targets");
        (kind.move_to)(&mut m, 0, Point2::new(1.0, 1.0));
        assert_eq!(m.fleet.targets[0].position, Point2::new(1.0, 1.0));
        (kind.add)(&mut m);
        assert_eq!(m.fleet.targets.len(), 3);
        // 10 s after the last, 1 m east of it.
        assert_eq!(m.fleet.targets[2].time, 30.0);
        assert_eq!(m.fleet.targets[2].position, Point2::new(-3.0, 2.0));
        (kind.remove)(&mut m, 0);
        assert_eq!(m.fleet.targets.len(), 2);
        assert_eq!(every_point(&m).len(), 2);
        assert!(
            !PointRef {
                index: 2,
                ..points[0]
            }
            .exists(&m)
        );
    }
}

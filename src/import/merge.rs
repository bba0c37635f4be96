//! The survey's obstacles into the mission, by name: a feature owns the
//! obstacles named after it (`name`, or `name #k` for its pieces). Importing
//! the same file again changes nothing; an updated survey updates the
//! obstacles it owns (shape, heights, kind, description: whether one is
//! inspected, its stand-off and its side stay the mission's), adds the
//! pieces it has now and removes those it no longer has. A default (no
//! radius, no height in the survey) never replaces what the mission knows.
//! What would lower, thin or remove a known obstacle is listed as a loss
//! ([`Changes::losses`]): the CLI writes it only with `--force`.

use std::fmt;

use super::obstacles::FeatureObstacles;
use crate::mission::{Mission, Obstacle};

/// Centres closer than this are the same, metres (a survey read again
/// through the geodesy comes back within micrometres).
const SAME_PLACE: f64 = 1e-3;

/// One change to the mission's obstacles.
#[derive(Debug, Clone, PartialEq)]
pub enum Change {
    Added(String),
    /// The obstacle, and what changed in words.
    Updated(String, String),
    /// The obstacle, and the feature that no longer makes it.
    Removed(String, String),
}

impl fmt::Display for Change {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Change::Added(name) => write!(f, "added '{name}'"),
            Change::Updated(name, what) => write!(f, "updated '{name}': {what}"),
            Change::Removed(name, owner) => {
                write!(
                    f,
                    "removed '{name}': the survey's '{owner}' no longer has it"
                )
            }
        }
    }
}

/// Every change, in order, and how many obstacles stayed as they were.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Changes {
    pub list: Vec<Change>,
    pub unchanged: usize,
    /// What the survey would take from a known obstacle: lower its top,
    /// raise its underside, thin it, shrink its footprint, remove it.
    pub losses: Vec<String>,
}

impl Changes {
    pub fn added(&self) -> impl Iterator<Item = &Change> {
        self.list.iter().filter(|c| matches!(c, Change::Added(_)))
    }

    pub fn updated(&self) -> impl Iterator<Item = &Change> {
        self.list
            .iter()
            .filter(|c| matches!(c, Change::Updated(..)))
    }

    pub fn removed(&self) -> impl Iterator<Item = &Change> {
        self.list
            .iter()
            .filter(|c| matches!(c, Change::Removed(..)))
    }

    /// The mission is as it was.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }
}

/// Names as a person reads a list of them: the pieces of one feature as a
/// run, `site office #1…#8`.
pub fn runs(names: &[&str]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut k = 0;
    while k < names.len() {
        let piece = |n: &str| -> Option<(String, usize)> {
            let (base, number) = n.rsplit_once(" #")?;
            Some((base.to_owned(), number.parse().ok()?))
        };
        match piece(names[k]) {
            Some((base, first)) => {
                let mut last = first;
                let mut j = k + 1;
                while let Some((b, n)) = names.get(j).and_then(|n| piece(n)) {
                    if b != base || n != last + 1 {
                        break;
                    }
                    last = n;
                    j += 1;
                }
                out.push(if last > first {
                    format!("'{base} #{first}…#{last}'")
                } else {
                    format!("'{}'", names[k])
                });
                k = j;
            }
            None => {
                out.push(format!("'{}'", names[k]));
                k += 1;
            }
        }
    }
    out.join(", ")
}

/// Whether the feature called `owner` owns the obstacle called `name`.
fn owns(owner: &str, name: &str) -> bool {
    name == owner
        || name
            .strip_prefix(owner)
            .and_then(|rest| rest.strip_prefix(" #"))
            .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
}

/// `mission` with the features' obstacles in it, and what changed.
pub fn merge(mission: &Mission, features: &[FeatureObstacles]) -> (Mission, Changes) {
    let mut m = mission.clone();
    let mut changes = Changes::default();
    for f in features {
        let keeps = |o: &Obstacle| f.obstacles.iter().any(|n| n.name == o.name);
        let mut gone = Vec::new();
        m.obstacles.retain(|o| {
            let drop = owns(&f.name, &o.name) && !keeps(o);
            if drop {
                gone.push(o.name.clone());
            }
            !drop
        });
        changes.losses.extend(gone.iter().map(|name| {
            format!(
                "'{name}' removed (the survey's '{}' no longer has it)",
                f.name
            )
        }));
        changes.list.extend(
            gone.into_iter()
                .map(|name| Change::Removed(name, f.name.clone())),
        );
        for surveyed in &f.obstacles {
            match m.obstacles.iter_mut().find(|o| o.name == surveyed.name) {
                Some(old) => {
                    let new = keep_known(old, surveyed, f);
                    match differences(old, &new) {
                        None => changes.unchanged += 1,
                        Some(what) => {
                            changes.losses.extend(losses(old, &new));
                            old.center = new.center;
                            old.radius = new.radius;
                            old.footprint = new.footprint.clone();
                            old.height = new.height;
                            old.base = new.base;
                            old.wire = new.wire.clone();
                            old.kind = new.kind.clone();
                            if new.description.is_some() {
                                old.description = new.description.clone();
                            }
                            changes.list.push(Change::Updated(new.name.clone(), what));
                        }
                    }
                }
                None => {
                    m.obstacles.push(surveyed.clone());
                    changes.list.push(Change::Added(surveyed.name.clone()));
                }
            }
        }
    }
    (m, changes)
}

/// The surveyed obstacle with what the survey did not know (a default
/// radius or height) taken from the mission's `old` one.
fn keep_known(old: &Obstacle, surveyed: &Obstacle, f: &FeatureObstacles) -> Obstacle {
    let mut new = surveyed.clone();
    if !f.height_known && !new.is_wire() {
        new.height = old.height;
        new.base = old.base;
    }
    if !f.radius_known && !new.is_wire() && new.footprint.is_empty() && old.footprint.is_empty() {
        new.radius = old.radius;
    }
    new
}

/// What `new` takes from `old`, in words: a lower top, a higher underside,
/// a thinner cylinder or wire, a smaller footprint.
fn losses(old: &Obstacle, new: &Obstacle) -> Vec<String> {
    use geo::Area;
    let mut out = Vec::new();
    let name = &old.name;
    if new.height < old.height - 1e-6 {
        out.push(format!(
            "'{name}' lowered: its top {} → {} m",
            old.height, new.height
        ));
    }
    if new.base > old.base + 1e-6 {
        out.push(format!(
            "'{name}' raised from below: its underside {} → {} m",
            old.base, new.base
        ));
    }
    let area = |o: &Obstacle| -> f64 {
        if o.footprint.len() >= 3 {
            let ring: Vec<geo::Coord<f64>> = o
                .footprint
                .iter()
                .map(|p| geo::coord! { x: p.x, y: p.y })
                .collect();
            geo::Polygon::new(geo::LineString::new(ring), Vec::new()).unsigned_area()
        } else {
            std::f64::consts::PI * o.radius * o.radius
        }
    };
    match (&old.wire, &new.wire) {
        (Some(a), Some(b)) if b.radius < a.radius - 1e-6 => out.push(format!(
            "'{name}' thinned: its radius {} → {} m",
            a.radius, b.radius
        )),
        (Some(_), _) | (_, Some(_)) => {}
        _ if old.footprint.is_empty() && new.footprint.is_empty() => {
            if new.radius < old.radius - 1e-6 {
                out.push(format!(
                    "'{name}' thinned: its radius {} → {} m",
                    old.radius, new.radius
                ));
            }
        }
        _ => {
            let (a, b) = (area(old), area(new));
            if b < a * (1.0 - 1e-6) - 1e-9 {
                out.push(format!(
                    "'{name}' made smaller: its footprint {a:.1} → {b:.1} m²"
                ));
            }
        }
    }
    out
}

/// What the survey changes in an obstacle, in words; `None` for nothing.
fn differences(old: &Obstacle, new: &Obstacle) -> Option<String> {
    let mut what = Vec::new();
    let moved = (new.center - old.center).norm();
    if moved > SAME_PLACE {
        what.push(format!("centre moved {moved:.3} m"));
    }
    if (new.radius - old.radius).abs() > 1e-6 {
        what.push(format!("radius {} → {} m", old.radius, new.radius));
    }
    if new.footprint != old.footprint {
        what.push(format!(
            "footprint of {} → {} vertices",
            old.footprint.len(),
            new.footprint.len()
        ));
    }
    if (new.height - old.height).abs() > 1e-6 {
        what.push(format!("height {} → {} m", old.height, new.height));
    }
    if (new.base - old.base).abs() > 1e-6 {
        what.push(format!("base {} → {} m", old.base, new.base));
    }
    if new.wire != old.wire && new.wire.is_some() && old.wire.is_some() {
        what.push("wire moved".to_owned());
    } else if new.wire.is_some() != old.wire.is_some() {
        what.push(format!("{} → {}", old.shape_name(), new.shape_name()));
    }
    if new.description.is_some() && new.description != old.description {
        what.push("description".to_owned());
    }
    if new.kind != old.kind {
        let show = |k: &Option<String>| k.clone().unwrap_or_else(|| "none".into());
        what.push(format!("kind {} → {}", show(&old.kind), show(&new.kind)));
    }
    (!what.is_empty()).then(|| what.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point2;

    fn obstacle(name: &str, x: f64) -> Obstacle {
        Obstacle::standing(name, Point2::new(x, 10.0), 1.0, 10.0)
    }

    #[test]
    fn pieces_of_one_feature_read_as_a_run() {
        let names = [
            "pier 1", "shed #1", "shed #2", "shed #3", "fence #2", "x #a",
        ];
        assert_eq!(runs(&names), "'pier 1', 'shed #1…#3', 'fence #2', 'x #a'");
    }

    #[test]
    fn a_feature_owns_its_name_and_its_numbered_pieces_only() {
        assert!(owns("shed", "shed") && owns("shed", "shed #3"));
        assert!(!owns("shed", "shed 2") && !owns("shed", "shed #") && !owns("shed", "shedder"));
        assert!(!owns("shed", "shed #2a"));
    }

    #[test]
    fn merging_twice_changes_nothing_and_an_update_keeps_the_missions_settings() {
        let mission = crate::mission::default_mission().mission;
        let survey = vec![FeatureObstacles {
            name: "shed".into(),
            obstacles: vec![obstacle("shed #1", 20.0), obstacle("shed #2", 22.0)],
            radius_known: true,
            height_known: true,
        }];
        let (once, first) = merge(&mission, &survey);
        assert_eq!(first.added().count(), 2);
        let (twice, second) = merge(&once, &survey);
        assert_eq!(twice, once);
        assert!(second.is_empty() && second.unchanged == 2);

        // The survey grows the shed by one piece and moves the first; the
        // mission had made the first inspected.
        let mut inspected = once.clone();
        if let Some(o) = inspected.obstacles.iter_mut().find(|o| o.name == "shed #1") {
            o.inspect = true;
        }
        let moved = vec![FeatureObstacles {
            name: "shed".into(),
            obstacles: vec![obstacle("shed #1", 20.5)],
            radius_known: true,
            height_known: true,
        }];
        let (after, changes) = merge(&inspected, &moved);
        let shed: Vec<&Obstacle> = after
            .obstacles
            .iter()
            .filter(|o| owns("shed", &o.name))
            .collect();
        assert_eq!(shed.len(), 1);
        assert!(shed[0].inspect && (shed[0].center.x - 20.5).abs() < 1e-12);
        assert_eq!(changes.removed().count(), 1);
        assert_eq!(changes.updated().count(), 1);
        assert_eq!(changes.losses.len(), 1, "the removed piece is a loss");
        assert!(
            changes
                .list
                .iter()
                .any(|c| c.to_string() == "updated 'shed #1': centre moved 0.500 m")
        );
        assert_eq!(after.obstacles.len(), mission.obstacles.len() + 1);
    }

    #[test]
    fn a_survey_without_a_height_keeps_the_known_one_and_a_lower_one_is_a_loss() {
        let mut mission = crate::mission::default_mission().mission;
        let mut mast = obstacle("mast", 20.0);
        mast.height = 30.0;
        mast.radius = 0.5;
        mission.obstacles.push(mast);
        // Surveyed again with defaults (no radius, no height): nothing changes.
        let mut default = obstacle("mast", 20.0);
        default.height = 21.0;
        let survey = vec![FeatureObstacles {
            name: "mast".into(),
            obstacles: vec![default.clone()],
            radius_known: false,
            height_known: false,
        }];
        let (same, changes) = merge(&mission, &survey);
        assert_eq!(same, mission);
        assert!(changes.is_empty() && changes.losses.is_empty());
        // Surveyed lower, its height known: an update that is a loss.
        let lower = vec![FeatureObstacles {
            height_known: true,
            radius_known: true,
            ..survey[0].clone()
        }];
        let (_, changes) = merge(&mission, &lower);
        assert_eq!(changes.losses, vec!["'mast' lowered: its top 30 → 21 m"]);
    }
}

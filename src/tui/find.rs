//! Find by name (`/`, as in vim and less): on a site of a hundred obstacles
//! stepping with `n` to one of them took 79 presses. Part of a name typed
//! narrows the obstacles and IWPs that have it; the first is selected as
//! the typing goes (the map pans to it), `↑`/`↓` choose another, `Enter`
//! keeps the choice and `Esc` goes back to what was selected before. After
//! `Enter`, `n` / `N` (and `p`) step through the same matches until `Esc`.
//!
//! This component owns the query, its matches and the cursor in them; the
//! app selects and pans (`App` carries the flows that cross components).

use nalgebra::Point2;

use super::action::Pane;
use super::fields::Item;
use crate::mission::Mission;
use crate::pipelines::theta_pso::Iwp;

/// What was on screen when the find began: `Esc` while typing goes back to it.
#[derive(Debug, Clone, PartialEq)]
pub struct Before {
    pub selected: Item,
    /// The map's panned centre (None: the extent's middle).
    pub center: Option<Point2<f64>>,
    pub pane: Pane,
}

/// The find: the prompt being typed, or the matches being stepped through.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Find {
    /// The prompt is open: keys type into the query.
    typing: bool,
    query: String,
    matches: Vec<Item>,
    /// Index into `matches`: the one selected.
    cursor: usize,
    /// Set from `/` until the find is kept or cancelled.
    before: Option<Before>,
}

impl Find {
    /// The prompt is open (keys type into it).
    pub fn is_typing(&self) -> bool {
        self.typing
    }

    /// A kept find's matches are being stepped through (`n` / `N`).
    pub fn is_stepping(&self) -> bool {
        !self.typing && !self.matches.is_empty()
    }

    pub fn query(&self) -> &str {
        &self.query
    }

    /// The items whose names hold the query, best first.
    pub fn matches(&self) -> &[Item] {
        &self.matches
    }

    /// Which of [`Find::matches`] is selected.
    pub fn cursor(&self) -> usize {
        self.cursor
    }

    /// The match selected, if any.
    pub fn current(&self) -> Option<&Item> {
        self.matches.get(self.cursor)
    }

    /// What was on screen when the find began, while it is typed.
    pub fn before(&self) -> Option<&Before> {
        self.before.as_ref()
    }

    /// Opens the prompt, empty; `before` is what `Esc` goes back to.
    pub fn start(&mut self, before: Before) {
        *self = Find {
            typing: true,
            before: Some(before),
            ..Find::default()
        };
    }

    /// The query changed: the matches narrow (or widen) to it, the first selected.
    pub fn set_query(&mut self, query: String, mission: &Mission, iwps: &[Iwp]) {
        self.matches = find(&query, mission, iwps);
        self.query = query;
        self.cursor = 0;
    }

    /// The matches again, for the mission as it is now (an edit may have
    /// added, renamed or removed one); the cursor on `selected` when it is
    /// one of them (a click may have selected another).
    pub fn refresh(&mut self, mission: &Mission, iwps: &[Iwp], selected: &Item) {
        self.matches = find(&self.query, mission, iwps);
        match self.matches.iter().position(|m| m == selected) {
            Some(k) => self.cursor = k,
            None => self.cursor = self.cursor.min(self.matches.len().saturating_sub(1)),
        }
    }

    /// Moves the cursor `by` matches, round the ends; the match now selected.
    pub fn step(&mut self, by: i32) -> Option<&Item> {
        let n = self.matches.len() as i64;
        if n == 0 {
            return None;
        }
        self.cursor = (self.cursor as i64 + i64::from(by)).rem_euclid(n) as usize;
        self.current()
    }

    /// `Enter`: the prompt closes, the matches stay for `n` / `N`.
    pub fn keep(&mut self) {
        self.typing = false;
        self.before = None;
    }

    /// `Esc` while typing: the prompt closes and the matches go; what was
    /// on screen before.
    pub fn cancel(&mut self) -> Option<Before> {
        let before = self.before.take();
        *self = Find::default();
        before
    }

    /// Ends stepping through the matches; false when there was nothing to end.
    pub fn end(&mut self) -> bool {
        let was = self.typing || !self.matches.is_empty();
        *self = Find::default();
        was
    }
}

/// How well a name holds the query: 0 is the name itself, 1 a name that
/// starts with it, 2 a word of the name that does, 3 anywhere in it.
fn rank(name: &str, query: &str) -> Option<u8> {
    let name = name.to_lowercase();
    if name == query {
        Some(0)
    } else if name.starts_with(query) {
        Some(1)
    } else if name
        .split(|c: char| !c.is_alphanumeric())
        .any(|w| !w.is_empty() && w.starts_with(query))
    {
        Some(2)
    } else {
        name.contains(query).then_some(3)
    }
}

/// The obstacles and IWPs whose names hold `query` (any case), the best
/// match first (see [`rank`]), obstacles before IWPs, then in the
/// mission's order. An IWP matches by either of its obstacles' names or
/// by its label (`a ↔ b`). An empty query matches nothing.
pub fn find(query: &str, mission: &Mission, iwps: &[Iwp]) -> Vec<Item> {
    let query = query.trim().to_lowercase();
    if query.is_empty() {
        return Vec::new();
    }
    let mut found: Vec<(u8, u8, usize, Item)> = Vec::new();
    for (i, o) in mission.obstacles.iter().enumerate() {
        if let Some(r) = rank(&o.name, &query) {
            found.push((r, 0, i, Item::Obstacle(i)));
        }
    }
    for (i, w) in iwps.iter().enumerate() {
        let label = format!("{} ↔ {}", w.between[0], w.between[1]);
        let best = [&w.between[0], &w.between[1], &label]
            .into_iter()
            .filter_map(|name| rank(name, &query))
            .min();
        if let Some(r) = best {
            found.push((r, 1, i, Item::Waypoint(w.between.clone())));
        }
    }
    found.sort_by_key(|(r, kind, i, _)| (*r, *kind, *i));
    found.into_iter().map(|(.., item)| item).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mission::default_mission;
    use crate::pipelines::theta_pso::find_iwps;

    #[test]
    fn names_that_start_with_the_query_come_before_those_that_hold_it() {
        let mut m = default_mission().mission;
        let first = m.obstacles[0].clone();
        for name in ["old mast", "mast 2", "mast", "topmast"] {
            m.obstacles.push(crate::mission::Obstacle {
                name: name.into(),
                ..first.clone()
            });
        }
        let n = m.obstacles.len();
        let found = find("MAST", &m, &[]);
        // 'mast' itself, 'mast 2' (starts with it), 'old mast' (a word
        // does), 'topmast' (holds it).
        assert_eq!(
            found,
            [
                Item::Obstacle(n - 2),
                Item::Obstacle(n - 3),
                Item::Obstacle(n - 4),
                Item::Obstacle(n - 1)
            ]
        );
        assert!(
            find("  ", &m, &[]).is_empty(),
            "an empty query finds nothing"
        );
        assert!(find("no such thing", &m, &[]).is_empty());
    }

    #[test]
    fn an_iwp_is_found_by_either_obstacles_name() {
        let m = default_mission().mission;
        let iwps = find_iwps(&m);
        let found = find("pole 4", &m, &iwps);
        let pole = m
            .obstacles
            .iter()
            .position(|o| o.name == "light pole 4")
            .unwrap();
        assert_eq!(found[0], Item::Obstacle(pole));
        assert!(
            found.contains(&Item::Waypoint(["light pole 4".into(), "pier 5".into()])),
            "{found:?}"
        );
        // The obstacles first, then the IWP between them.
        assert!(matches!(found.last(), Some(Item::Waypoint(_))), "{found:?}");
    }

    #[test]
    fn stepping_goes_round_the_ends_and_cancel_gives_back_what_was() {
        let m = default_mission().mission;
        let mut f = Find::default();
        let before = Before {
            selected: Item::Goal,
            center: None,
            pane: Pane::Map,
        };
        f.start(before.clone());
        assert!(f.is_typing() && !f.is_stepping());
        f.set_query("pier".into(), &m, &[]);
        let piers = f.matches().len();
        assert!(piers >= 3, "{:?}", f.matches());
        assert_eq!(f.cursor(), 0);
        let first = f.current().cloned();
        assert_eq!(f.step(-1).cloned(), f.matches().last().cloned());
        assert_eq!(f.step(1).cloned(), first);
        assert_eq!(f.cancel(), Some(before));
        assert!(f.matches().is_empty() && !f.is_typing());

        f.start(Before {
            selected: Item::Mission,
            center: None,
            pane: Pane::Map,
        });
        f.set_query("pier".into(), &m, &[]);
        f.keep();
        assert!(f.is_stepping(), "kept: n / N step through the matches");
        assert_eq!(f.cancel(), None, "a kept find has nothing to go back to");
        assert!(!f.end(), "nothing left to end");
    }
}

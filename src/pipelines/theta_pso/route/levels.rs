//! The altitudes the route stage searches at: which obstacles stand in the
//! way at each, and where the formation may climb between them.
//!
//! The θ-PSO paper's obstacles are cylinders of height z_k and its paths are
//! 3-D (Section III-A); the cost (eq. 4 above and below a prism) and
//! verification measure in three dimensions. The route stage searches the
//! plane, so it reads altitude as *levels*: at each level the centroid flies
//! at one altitude (or, for the first search, anywhere between the start's
//! and the goal's), and an obstacle is in the way there unless the formation
//! passes over it (its lowest UAV above the top by r_Q + the safety margin +
//! the cost's clearance margin) or under it (its highest UAV as far below
//! the base). Between two levels the formation climbs (or descends) where
//! every altitude between them is clear, over a short ramp.
//!
//! The first search is *flat*: one level spanning the start's and the goal's
//! altitudes, what the paper's swarm flies when nothing forces a climb. When
//! it finds no corridor, the search is *stacked*: the start's and the goal's
//! altitudes, each inspection's, and the altitudes that pass over (under)
//! the obstacles in the way, those of the chain that closed the flat search
//! first ([`MAX_LEVELS`] in all).

use crate::mission::{Mission, Obstacle};

/// Most levels a stacked search holds (the start's and the goal's included):
/// the search's states grow with them.
pub const MAX_LEVELS: usize = 8;

/// Altitudes closer than this are one candidate level, the one that passes
/// all of them kept (metres).
const CLUSTER: f64 = 0.75;

/// Whether `o` stands in the way of a formation whose centroid flies
/// anywhere in `span` (metres): it reaches into the band, and the formation
/// passes neither over it at the span's lowest nor under it at its highest.
pub fn blocks(mission: &Mission, o: &Obstacle, span: [f64; 2]) -> bool {
    let [over, under] = mission.passing_altitudes(o);
    o.within(mission.bounds.z) && !(over <= span[0] || span[1] <= under)
}

/// The levels of one search.
#[derive(Debug, Clone, PartialEq)]
pub struct Levels {
    /// Per level, lowest first, the centroid altitudes it spans: one
    /// altitude, or (flat) the start's to the goal's.
    spans: Vec<[f64; 2]>,
    /// The flat search: its corridor's heights are left to the seeding.
    flat: bool,
    /// The levels of the start and of the goal.
    pub start: usize,
    pub goal: usize,
}

impl Levels {
    /// The flat search's one level: between the start's and the goal's
    /// altitudes, in the band.
    pub fn flat(mission: &Mission) -> Self {
        let z = mission.bounds.z;
        let band = |v: f64| v.clamp(z[0], z[1].max(z[0]));
        let (start, goal) = (mission.route.start.z, mission.route.goal.z);
        Levels {
            spans: vec![[band(start.min(goal)), band(start.max(goal))]],
            flat: true,
            start: 0,
            goal: 0,
        }
    }

    /// Levels at single altitudes in `z_box` (the centroid's range): the
    /// start's, the goal's, one in each of `passes` (each inspection's
    /// altitudes) when none of the others is, and those passing over (under)
    /// the obstacles in the band, clustered, the ones over (under) the whole
    /// of `chain` (the obstacles that closed the flat search) first.
    pub fn stacked(
        mission: &Mission,
        z_box: [f64; 2],
        passes: &[[f64; 2]],
        chain: &[usize],
    ) -> Self {
        let clamp = |v: f64| v.clamp(z_box[0], z_box[1].max(z_box[0]));
        let (zs, zg) = (clamp(mission.route.start.z), clamp(mission.route.goal.z));
        let mut fixed = vec![zs, zg];
        for range in passes {
            if !fixed.iter().any(|z| range[0] <= *z && *z <= range[1]) {
                fixed.push(zs.clamp(range[0], range[1].max(range[0])));
            }
        }
        // Candidates: (altitude, obstacles it passes, holds a chain member).
        let in_box = |z: f64| z_box[0] <= z && z <= z_box[1];
        let mut overs: Vec<(f64, usize)> = Vec::new();
        let mut unders: Vec<(f64, usize)> = Vec::new();
        for (k, o) in mission.obstacles.iter().enumerate() {
            if !o.within(mission.bounds.z) {
                continue;
            }
            let [over, under] = mission.passing_altitudes(o);
            if over.is_finite() && in_box(over) {
                overs.push((over, k));
            }
            if under > z_box[0] && in_box(under) {
                unders.push((under, k));
            }
        }
        let in_chain = |k: usize| chain.contains(&k);
        let mut candidates: Vec<(f64, usize, bool)> = Vec::new();
        // Over (under) the whole chain: the altitude passing every member
        // that can be passed that way.
        let chain_over = overs
            .iter()
            .filter(|(_, k)| in_chain(*k))
            .map(|(z, _)| *z)
            .fold(f64::NEG_INFINITY, f64::max);
        let chain_under = unders
            .iter()
            .filter(|(_, k)| in_chain(*k))
            .map(|(z, _)| *z)
            .fold(f64::INFINITY, f64::min);
        for z in [chain_over, chain_under] {
            if z.is_finite() {
                candidates.push((z, usize::MAX, true));
            }
        }
        candidates.extend(clusters(&mut overs, true, &in_chain));
        candidates.extend(clusters(&mut unders, false, &in_chain));
        // The chain's first, then the larger clusters.
        candidates.sort_by(|a, b| b.2.cmp(&a.2).then(b.1.cmp(&a.1)));
        let mut chosen = fixed.clone();
        for (z, _, _) in candidates {
            if chosen.len() >= MAX_LEVELS {
                break;
            }
            if !chosen.iter().any(|c| (c - z).abs() < 1e-6) {
                chosen.push(z);
            }
        }
        chosen.sort_by(f64::total_cmp);
        chosen.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        let level_of = |z: f64| {
            chosen
                .iter()
                .position(|c| (c - z).abs() < 1e-9)
                .unwrap_or(0)
        };
        Levels {
            start: level_of(zs),
            goal: level_of(zg),
            spans: chosen.iter().map(|&z| [z, z]).collect(),
            flat: false,
        }
    }

    pub fn len(&self) -> usize {
        self.spans.len()
    }

    pub fn is_empty(&self) -> bool {
        self.spans.is_empty()
    }

    pub fn is_flat(&self) -> bool {
        self.flat
    }

    /// The altitudes level `l` spans.
    pub fn span(&self, l: usize) -> [f64; 2] {
        self.spans[l]
    }

    /// The altitude of level `l` (the lowest of the flat level's).
    pub fn altitude(&self, l: usize) -> f64 {
        self.spans[l][0]
    }

    /// What a climb between level `pair` and the one above sweeps.
    pub fn hull(&self, pair: usize) -> [f64; 2] {
        let (a, b) = (self.spans[pair], self.spans[pair + 1]);
        [a[0].min(b[0]), a[1].max(b[1])]
    }

    /// The level whose altitude is `z` (a corridor's height), if any.
    pub fn level_of(&self, z: f64) -> Option<usize> {
        self.spans
            .iter()
            .position(|s| s[0] <= z + 1e-6 && z <= s[1] + 1e-6)
    }
}

/// Candidate altitudes from `values` (altitude, obstacle), sorted and
/// grouped within [`CLUSTER`]: over obstacles (`over`) the group's highest,
/// which passes all of it, under them its lowest; with the group's size and
/// whether it holds a member of the chain.
fn clusters(
    values: &mut [(f64, usize)],
    over: bool,
    in_chain: &dyn Fn(usize) -> bool,
) -> Vec<(f64, usize, bool)> {
    values.sort_by(|a, b| a.0.total_cmp(&b.0));
    if !over {
        values.reverse();
    }
    let mut out = Vec::new();
    let mut i = 0;
    while i < values.len() {
        let first = values[i].0;
        let mut j = i;
        let mut chained = false;
        while j < values.len() && (values[j].0 - first).abs() <= CLUSTER {
            chained |= in_chain(values[j].1);
            j += 1;
        }
        out.push((values[j - 1].0, j - i, chained));
        i = j;
    }
    out
}

//! The open list's entry of the shortest-route searches (the detours round
//! discs, the route stage's coarse guide): a node and its key, popped from a
//! `BinaryHeap` smallest key first, ties to the lowest node so a search is
//! the same on every run.

use std::cmp::Ordering;

/// A node on an open list and its key (a distance, or an estimate of one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nearest {
    pub key: f64,
    pub node: usize,
}

impl Eq for Nearest {}

impl Ord for Nearest {
    fn cmp(&self, other: &Self) -> Ordering {
        // Reversed: `BinaryHeap` pops its greatest, the smallest key here.
        other
            .key
            .total_cmp(&self.key)
            .then(other.node.cmp(&self.node))
    }
}

impl PartialOrd for Nearest {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BinaryHeap;

    /// The heap gives the smallest key first, and the lowest node of equal keys.
    #[test]
    fn the_smallest_key_comes_first_then_the_lowest_node() {
        let mut heap: BinaryHeap<Nearest> = [(3.0, 0), (1.0, 7), (1.0, 2), (2.5, 1)]
            .into_iter()
            .map(|(key, node)| Nearest { key, node })
            .collect();
        let order: Vec<usize> = std::iter::from_fn(|| heap.pop().map(|n| n.node)).collect();
        assert_eq!(order, [2, 7, 1, 0]);
    }
}

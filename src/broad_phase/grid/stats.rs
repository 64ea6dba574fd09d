//! What a grid query cost: the slides' cost model `Tc = Nv*Cv + Nn*Cn + Ns*Cs` specialised to a
//! uniform grid (cells looked up, list entries read, exact box tests), so a debug view can show
//! "the car's cells and its candidate buildings" and a benchmark can explain its timings.

use std::ops::{Add, AddAssign};

/// Work done by one query (or, summed with `+=`, by many).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GridQueryStats {
    /// Cells looked up in the hash table (empty cells included).
    pub cells_visited: usize,
    /// Object entries read: cell-list entries (an object listed in several visited cells counts
    /// once per cell), oversize objects, and objects read by a scan.
    pub candidates_listed: usize,
    /// Exact AABB-AABB tests (one per distinct candidate; zero for candidate-only queries).
    pub exact_tests: usize,
    /// Queries that scanned every object instead of visiting cells, because they touched more
    /// cells than the grid holds objects.
    pub object_scans: usize,
    /// Queries answered from a [`super::GridQueryCache`]'s kept list, without visiting cells.
    pub reused_queries: usize,
}

impl AddAssign for GridQueryStats {
    fn add_assign(&mut self, other: Self) {
        self.cells_visited += other.cells_visited;
        self.candidates_listed += other.candidates_listed;
        self.exact_tests += other.exact_tests;
        self.object_scans += other.object_scans;
        self.reused_queries += other.reused_queries;
    }
}

impl Add for GridQueryStats {
    type Output = Self;

    fn add(mut self, other: Self) -> Self {
        self += other;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_add_every_counter() {
        let a = GridQueryStats {
            cells_visited: 1,
            candidates_listed: 2,
            exact_tests: 3,
            object_scans: 0,
            reused_queries: 2,
        };
        let b = GridQueryStats {
            cells_visited: 10,
            candidates_listed: 20,
            exact_tests: 30,
            object_scans: 1,
            reused_queries: 20,
        };
        let expected = GridQueryStats {
            cells_visited: 11,
            candidates_listed: 22,
            exact_tests: 33,
            object_scans: 1,
            reused_queries: 22,
        };
        assert_eq!(a + b, expected);
        let mut c = a;
        c += b;
        assert_eq!(c, expected);
    }
}

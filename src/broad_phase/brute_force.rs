//! The slides' brute force: test every pair of boxes, n(n−1)/2 tests per commit. The
//! reference the other broad phases are checked against, and the baseline of the benches.

use super::body_store::BodyStore;
use super::pair_diff::PairHistory;
use super::{BodyKind, BroadPhase, BroadPhaseError, Pair, ProxyId, StepStats};
use crate::bounding::Aabb;

/// All-pairs broad phase.
#[derive(Debug, Default)]
pub struct BruteForce {
    bodies: BodyStore,
    history: PairHistory,
    stats: StepStats,
}

impl BruteForce {
    /// An empty broad phase.
    pub fn new() -> Self {
        Self::default()
    }
}

impl BroadPhase for BruteForce {
    fn insert(&mut self, id: ProxyId, aabb: Aabb, kind: BodyKind) -> Result<(), BroadPhaseError> {
        self.bodies.insert(id, aabb, kind)
    }

    fn insert_bulk(&mut self, bodies: &[(ProxyId, Aabb, BodyKind)]) -> Result<(), BroadPhaseError> {
        self.bodies.insert_bulk(bodies)
    }

    fn update(&mut self, id: ProxyId, aabb: Aabb) -> Result<(), BroadPhaseError> {
        self.bodies.update(id, aabb)
    }

    fn remove(&mut self, id: ProxyId) -> Result<(), BroadPhaseError> {
        self.bodies.remove(id)
    }

    fn commit(&mut self) {
        let (ids, aabbs, kinds) = (self.bodies.ids(), self.bodies.aabbs(), self.bodies.kinds());
        let out = self.history.begin();
        for i in 0..ids.len() {
            for j in i + 1..ids.len() {
                if !BodyKind::both_static(kinds[i], kinds[j]) && aabbs[i].intersects(&aabbs[j]) {
                    out.push(Pair::ordered(ids[i], ids[j]));
                }
            }
        }
        let n = ids.len() as u64;
        // The oracle rebuilds whatever changed.
        self.stats = StepStats {
            rebuilt: true,
            endpoint_swaps: 0,
            pair_tests: n * n.saturating_sub(1) / 2,
            changed: self.bodies.take_changed(),
        };
        self.history.finish();
    }

    fn pairs(&self) -> &[Pair] {
        self.history.current()
    }

    fn added(&self) -> &[Pair] {
        self.history.added()
    }

    fn removed(&self) -> &[Pair] {
        self.history.removed()
    }

    fn stats(&self) -> StepStats {
        self.stats
    }

    fn memory_bytes(&self) -> usize {
        self.bodies.memory_bytes() + self.history.memory_bytes()
    }

    fn len(&self) -> usize {
        self.bodies.len()
    }

    fn contains(&self, id: ProxyId) -> bool {
        self.bodies.contains(id)
    }

    fn aabb(&self, id: ProxyId) -> Option<Aabb> {
        self.bodies.aabb(id)
    }
}

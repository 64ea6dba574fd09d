//! Sweep and prune that falls back to sorting from scratch when insertion sort is losing
//! (issue 12's adaptive sorting, at the level of the whole structure).
//!
//! The incremental SAP ([`IncrementalSap`]) costs `O(n + swaps)` a step, the sort and sweep
//! from scratch ([`SortAndSweep`], on the axis where the centres spread most) `O(n log n +
//! overlaps on that axis)` whatever the motion. Measured on the 10k cloud (`src/broad_phase/
//! sap.rs`' table), one endpoint swap costs about a tenth of what one `n log₂ n` unit of the
//! rebuild costs, so insertion sort loses once a step makes more than about ten swaps per `n
//! log₂ n`: bodies moving far relative to their spacing, or bodies strung along one axis, whose
//! intervals on the other two all overlap (a row of 10k boxes made 16M swaps a step).
//!
//! The rule: after each commit of the incremental SAP in which a box came, went or moved (a
//! commit re-sending the same boxes says nothing about the motion), a step with more than
//! [`AdaptiveSweep::SWAPS_PER_SORT_UNIT`]` · n log₂ n` swaps (times `√(n / 10k)` past 10k
//! bodies, where the rebuild starts missing the cache) is a strike for each whole budget it
//! spent; two strikes in a row (one commit at twice the budget, or two just over it) move every
//! body into a sort and sweep. Every [`AdaptiveSweep::PROBE_PERIOD`] such commits
//! the bodies go back to the SAP to see whether the motion has calmed (if not, one or two
//! commits later they return). A switch costs one bulk insertion; it changes no pair, and the
//! commit that switches reports the changes the old structure found. The SAP also gives up a
//! commit once it has spent the budgets that would switch anyway (its insertion sorts stop
//! there, and the sort from scratch takes over at once, the commit's changes diffed from the
//! pairs before it): a losing commit costs at most two budgets, not the 23 a 10,000-ball net's
//! second commit spent.
//!
//! From [`AdaptiveSweep::REGION_SCENE`] bodies the whole-scene lists are dense whatever the
//! motion (100k boxes all moving: 4.3× slower than parry's tree, `peers/benches/broad_phase.rs`),
//! and the bodies move into the segmented SAP ([`RegionSweep`]: 1.3× slower there, and 2× faster
//! than the SAP with 1 % moving); they come back below half that count.
//!
//! Smaller scenes move into the segmented SAP too while their motion is *dense*: from
//! [`AdaptiveSweep::DENSE_SCENE`] bodies, two commits in a row that each made more than
//! [`AdaptiveSweep::DENSE_SWAPS_PER_BODY`] swaps per body (but not enough for a strike) send
//! them there, and every [`AdaptiveSweep::PROBE_PERIOD`] commits they come back to see whether
//! the motion has calmed. Each endpoint then passes only its own region's endpoints.
//! A sort from scratch moves there too, on the same terms, while its sweep axis is
//! *crowded*: two commits in a row whose sweeps each made more than
//! [`AdaptiveSweep::DENSE_TESTS_PER_BODY`] box tests per body that found no pair. Bodies
//! hanging in one vertical plane, as the joint grid's net of 10,000 balls, share their
//! intervals column by column on either axis of the plane (49 idle tests a body): in the
//! regions the net's broad phase takes 10 million instructions a step instead of 16.6
//! (`valgrind --tool=callgrind`; the 10k cloud, mixed sizes and the row make under one).
//! Such a scene probes back like dense motion: every [`AdaptiveSweep::PROBE_PERIOD`] commits
//! it costs one losing incremental commit and two sweeps from scratch (one more fallback
//! counted each time). Idle tests count static pairs too, which the regions test as well. Measured
//! in one run of `peers/benches/broad_phase.rs` (swaps per body per commit: SAP time →
//! segmented time): the 10k cloud 58: 2.48 → 1.75–1.81 ms (two runs), 10k boxes of mixed sizes 34: 1.98 →
//! 1.96 ms, the 1k cloud 12: 0.135 → 0.127 ms; and 10,000 balls flying in a box
//! (`peers/benches/whole_step.rs`) make 35: their whole step fell by a quarter of its
//! instructions. A resting or settling pile makes under 5.

use super::pair_diff::diff_sorted;
use super::{
    BodyKind, BroadPhase, BroadPhaseError, IncrementalSap, Pair, ProxyId, RegionSweep,
    SortAndSweep, StepStats,
};
use crate::bounding::Aabb;
use std::mem::size_of;

/// The structure in use.
#[derive(Debug)]
enum Engine {
    Incremental(Box<IncrementalSap>),
    FromScratch(Box<SortAndSweep>),
    Regions(Box<RegionSweep>),
}

impl Engine {
    fn get(&self) -> &dyn BroadPhase {
        match self {
            Self::Incremental(sap) => sap.as_ref(),
            Self::FromScratch(sweep) => sweep.as_ref(),
            Self::Regions(regions) => regions.as_ref(),
        }
    }

    fn get_mut(&mut self) -> &mut dyn BroadPhase {
        match self {
            Self::Incremental(sap) => sap.as_mut(),
            Self::FromScratch(sweep) => sweep.as_mut(),
            Self::Regions(regions) => regions.as_mut(),
        }
    }
}

/// An incremental sweep and prune that switches to sorting from scratch while insertion sort
/// loses (see the module doc).
#[derive(Debug)]
pub struct AdaptiveSweep {
    engine: Engine,
    /// Per id: its kind while present (a switch moves every present body).
    kinds: Vec<Option<BodyKind>>,
    /// Strikes of the incremental SAP's losing commits in a row (one per whole budget spent).
    strikes: u32,
    /// Commits since the last switch.
    since_switch: u32,
    /// Switches to sorting from scratch so far.
    fallbacks: u64,
    /// Dense commits of the incremental SAP in a row (more than
    /// [`Self::DENSE_SWAPS_PER_BODY`] swaps per body, no strike).
    dense: u32,
    /// Whether the bodies are in the regions for their motion (they probe back), not for the
    /// scene's size (they leave below half of [`Self::REGION_SCENE`]).
    regions_for_motion: bool,
    /// The changes of a commit that switched (the old structure's, or after a commit the SAP
    /// gave up, the diff from the pairs before it), reported until the next commit.
    switched: Option<(Vec<Pair>, Vec<Pair>)>,
    /// Buffers for a switch.
    moving: Vec<(ProxyId, Aabb, BodyKind)>,
}

impl Default for AdaptiveSweep {
    fn default() -> Self {
        Self {
            engine: Engine::Incremental(Box::default()),
            kinds: Vec::new(),
            strikes: 0,
            since_switch: 0,
            fallbacks: 0,
            dense: 0,
            regions_for_motion: false,
            switched: None,
            moving: Vec::new(),
        }
    }
}

impl AdaptiveSweep {
    /// Swaps per `n log₂ n` above which a commit counts as a strike against insertion sort, up
    /// to [`Self::CACHE_SCENE`] bodies.
    pub const SWAPS_PER_SORT_UNIT: f64 = 10.0;
    /// Bodies from which the rebuild's cost per `n log₂ n` grows with the scene, about as `√n`
    /// (its random accesses miss the cache: 35 ns a unit at 10k bodies, 109 ns at 100k, while a
    /// swap stays near 3.3 ns), so the swap budget grows with it.
    pub const CACHE_SCENE: f64 = 10_000.0;
    /// Strikes in a row that trigger the fallback: a losing commit is one strike per whole swap
    /// budget it spent (commits that moved nothing are not counted, here and below).
    pub const STRIKES: u32 = 2;
    /// Commits after which sorting from scratch, or the segmented SAP entered for dense
    /// motion, hands the bodies back to the incremental SAP to try again.
    pub const PROBE_PERIOD: u32 = 120;

    /// Bodies from which they move into the segmented SAP (and below half of which they leave
    /// it).
    pub const REGION_SCENE: usize = 20_000;

    /// Swaps per body of a commit above which the motion counts as dense (see the module doc;
    /// the 10k cloud makes 58 and gains 30 % in the regions, boxes of mixed sizes make 34 and
    /// gain nothing, a settling pile makes under 5).
    pub const DENSE_SWAPS_PER_BODY: f64 = 20.0;

    /// Box tests per body that found no pair, in a sweep from scratch, above which its sweep
    /// axis counts as crowded (see the module doc).
    pub const DENSE_TESTS_PER_BODY: f64 = 16.0;

    /// Dense commits in a row that move the bodies into the segmented SAP.
    pub const DENSE_COMMITS: u32 = 2;

    /// Bodies from which dense motion moves them into the segmented SAP (a smaller scene's
    /// sweep costs microseconds either way).
    pub const DENSE_SCENE: usize = 1_000;

    /// An empty broad phase (it starts incremental).
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether the bodies are in the sort and sweep from scratch now.
    pub fn is_sorting_from_scratch(&self) -> bool {
        matches!(self.engine, Engine::FromScratch(_))
    }

    /// Whether the bodies are in the segmented SAP now (a large scene, or dense motion).
    pub fn is_in_regions(&self) -> bool {
        matches!(self.engine, Engine::Regions(_))
    }

    /// How many times insertion sort was found losing and the bodies moved to the sort from
    /// scratch.
    pub fn fallbacks(&self) -> u64 {
        self.fallbacks
    }

    /// Swaps a commit of `n` bodies may make before insertion sort counts as losing.
    fn swap_budget(n: usize) -> f64 {
        let n = n.max(2) as f64;
        let cache = (n / Self::CACHE_SCENE).max(1.0).sqrt();
        Self::SWAPS_PER_SORT_UNIT * cache * n * n.log2()
    }

    /// After an incremental commit that gave up past the budgets left before the rule switches
    /// (`STRIKES` less the strikes so far): every body moves
    /// into a sort from scratch, and the commit reports the changes from the pairs before it
    /// (the pairs the SAP lists less its net additions so far, plus its net removals so far).
    fn fall_back_from_abandoned(&mut self) {
        let Engine::Incremental(sap) = &self.engine else {
            return;
        };
        let mut before: Vec<Pair> = sap.pairs().to_vec();
        let added_so_far = sap.added();
        before.retain(|p| added_so_far.binary_search(p).is_err());
        before.extend_from_slice(sap.removed());
        before.sort_unstable();
        self.switch_to(Engine::FromScratch(Box::default()), Some(&before));
    }

    /// The switch the last commit's work calls for, if any.
    fn next_engine(&mut self) -> Option<Engine> {
        self.since_switch += 1;
        let large = self.engine.get().len() >= Self::REGION_SCENE;
        let probe = self.since_switch >= Self::PROBE_PERIOD;
        match &self.engine {
            Engine::Incremental(_) if large => self.regions_entered(false),
            Engine::Regions(_) if large => {
                // In for the scene's size now, whatever brought it: it leaves by that rule.
                self.regions_for_motion = false;
                None
            }
            Engine::Regions(_) if self.regions_for_motion => {
                probe.then(|| Engine::Incremental(Box::default()))
            }
            Engine::Regions(regions) => (regions.len() < Self::REGION_SCENE / 2)
                .then(|| Engine::Incremental(Box::default())),
            Engine::Incremental(sap) => {
                let (n, swaps) = (sap.len(), sap.stats().endpoint_swaps as f64);
                // A losing commit is as many strikes as whole budgets it spent: a commit that
                // swapped ten budgets' worth will not do better next time, and waiting for a
                // second strike cost the 10,000-ball net one commit of 30M swaps (1.2 billion
                // instructions, a sixth of its first 60 steps).
                let spent = swaps / Self::swap_budget(n);
                self.strikes = if spent > 1.0 {
                    self.strikes.saturating_add(spent as u32)
                } else {
                    0
                };
                let dense = spent <= 1.0
                    && n >= Self::DENSE_SCENE
                    && swaps > Self::DENSE_SWAPS_PER_BODY * n as f64;
                self.dense = if dense { self.dense + 1 } else { 0 };
                if self.strikes >= Self::STRIKES {
                    Some(Engine::FromScratch(Box::default()))
                } else if self.dense >= Self::DENSE_COMMITS {
                    self.regions_entered(true)
                } else {
                    None
                }
            }
            Engine::FromScratch(_) if large => self.regions_entered(false),
            Engine::FromScratch(sweep) => {
                let (n, tests) = (sweep.len(), sweep.stats().pair_tests as f64);
                let idle = tests - sweep.pairs().len() as f64;
                let dense = n >= Self::DENSE_SCENE && idle > Self::DENSE_TESTS_PER_BODY * n as f64;
                self.dense = if dense { self.dense + 1 } else { 0 };
                if self.dense >= Self::DENSE_COMMITS {
                    self.regions_entered(true)
                } else {
                    probe.then(|| Engine::Incremental(Box::default()))
                }
            }
        }
    }

    /// The segmented SAP, entered for the motion (it probes back) or for the scene's size.
    fn regions_entered(&mut self, for_motion: bool) -> Option<Engine> {
        self.regions_for_motion = for_motion;
        Some(Engine::Regions(Box::default()))
    }

    /// Moves every body into `next`, keeping this commit's changes to report: the old
    /// structure's, or with `before` (sorted) the difference from those pairs to the new
    /// structure's.
    fn switch_to(&mut self, mut next: Engine, before: Option<&[Pair]>) {
        let old = self.engine.get();
        self.moving.clear();
        for (id, kind) in self.kinds.iter().enumerate() {
            if let (Some(kind), Some(aabb)) = (kind, old.aabb(id as ProxyId)) {
                self.moving.push((id as ProxyId, aabb, *kind));
            }
        }
        let old_changes = (old.added().to_vec(), old.removed().to_vec());
        let new = next.get_mut();
        // The boxes were accepted once: a bulk insertion of them cannot fail.
        if new.insert_bulk(&self.moving).is_ok() {
            new.commit();
            let changes = match before {
                Some(before) => changes_since(before, new.pairs()),
                None => old_changes,
            };
            if matches!(next, Engine::FromScratch(_)) {
                self.fallbacks += 1;
            }
            self.engine = next;
            self.switched = Some(changes);
        }
        self.strikes = 0;
        self.dense = 0;
        self.since_switch = 0;
    }
}

impl BroadPhase for AdaptiveSweep {
    fn insert(&mut self, id: ProxyId, aabb: Aabb, kind: BodyKind) -> Result<(), BroadPhaseError> {
        self.engine.get_mut().insert(id, aabb, kind)?;
        let slot = id as usize;
        if self.kinds.len() <= slot {
            self.kinds.resize(slot + 1, None);
        }
        self.kinds[slot] = Some(kind);
        Ok(())
    }

    fn insert_bulk(&mut self, bodies: &[(ProxyId, Aabb, BodyKind)]) -> Result<(), BroadPhaseError> {
        self.engine.get_mut().insert_bulk(bodies)?;
        let top = bodies.iter().map(|b| b.0 as usize + 1).max().unwrap_or(0);
        if self.kinds.len() < top {
            self.kinds.resize(top, None);
        }
        for &(id, _, kind) in bodies {
            self.kinds[id as usize] = Some(kind);
        }
        Ok(())
    }

    fn update(&mut self, id: ProxyId, aabb: Aabb) -> Result<(), BroadPhaseError> {
        self.engine.get_mut().update(id, aabb)
    }

    fn remove(&mut self, id: ProxyId) -> Result<(), BroadPhaseError> {
        self.engine.get_mut().remove(id)?;
        if let Some(kind) = self.kinds.get_mut(id as usize) {
            *kind = None;
        }
        Ok(())
    }

    fn commit(&mut self) {
        self.switched = None;
        // Insertion sort gives up where the rule would switch anyway (a 10,000-ball net's
        // second commit made 30M swaps, 23 budgets, before it could count as a strike).
        // A scene large enough for the regions switches there instead, whatever the swaps.
        if let Engine::Incremental(sap) = &mut self.engine {
            let cap = if sap.len() >= Self::REGION_SCENE {
                u64::MAX
            } else {
                let strikes_left = Self::STRIKES.saturating_sub(self.strikes).max(1);
                (f64::from(strikes_left) * Self::swap_budget(sap.len())) as u64
            };
            sap.set_max_swaps(cap);
        }
        self.engine.get_mut().commit();
        if matches!(&self.engine, Engine::Incremental(sap) if sap.abandoned()) {
            self.fall_back_from_abandoned();
            return;
        }
        // Only commits in which a box came, went or moved count for the rule: a game's
        // schedule may commit again with nothing moved (the ECS commits at the step's start
        // and in its substep; until the eighteenth stop the substep re-sent unchanged boxes),
        // and such a commit, swapping nothing, once cleared every strike, so a net of 10,000
        // balls making 30M swaps a step never fell back.
        if !self.engine.get().stats().changed {
            return;
        }
        if let Some(next) = self.next_engine() {
            self.switch_to(next, None);
        }
    }

    fn pairs(&self) -> &[Pair] {
        self.engine.get().pairs()
    }

    fn added(&self) -> &[Pair] {
        match &self.switched {
            Some((added, _)) => added,
            None => self.engine.get().added(),
        }
    }

    fn removed(&self) -> &[Pair] {
        match &self.switched {
            Some((_, removed)) => removed,
            None => self.engine.get().removed(),
        }
    }

    fn stats(&self) -> StepStats {
        self.engine.get().stats()
    }

    fn memory_bytes(&self) -> usize {
        self.engine.get().memory_bytes()
            + self.kinds.capacity() * size_of::<Option<BodyKind>>()
            + self.moving.capacity() * size_of::<(ProxyId, Aabb, BodyKind)>()
    }

    fn len(&self) -> usize {
        self.engine.get().len()
    }

    fn contains(&self, id: ProxyId) -> bool {
        self.engine.get().contains(id)
    }

    fn aabb(&self, id: ProxyId) -> Option<Aabb> {
        self.engine.get().aabb(id)
    }
}

/// The pairs added and removed from sorted `before` to `now` (in any order).
fn changes_since(before: &[Pair], now: &[Pair]) -> (Vec<Pair>, Vec<Pair>) {
    let mut now = now.to_vec();
    now.sort_unstable();
    let (mut added, mut removed) = (Vec::new(), Vec::new());
    diff_sorted(before, &now, &mut added, &mut removed);
    (added, removed)
}

#[cfg(test)]
#[path = "adaptive_tests.rs"]
mod tests;

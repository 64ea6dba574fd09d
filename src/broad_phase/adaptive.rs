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
//! the motion has calmed. Each endpoint then passes only its own region's endpoints. Measured
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
                } else if self.dense >= Self::STRIKES {
                    self.regions_entered(true)
                } else {
                    None
                }
            }
            Engine::FromScratch(_) if large => self.regions_entered(false),
            Engine::FromScratch(_) => probe.then(|| Engine::Incremental(Box::default())),
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

/// The pairs of `a` and `b` as sorted sets are equal (a test helper: the structures list
/// pairs in different orders).
#[cfg(test)]
fn same_pairs(a: &[Pair], b: &[Pair]) -> bool {
    let mut a = a.to_vec();
    a.sort_unstable();
    let (added, removed) = changes_since(&a, b);
    added.is_empty() && removed.is_empty()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::broad_phase::BruteForce;
    use glam::Vec3;

    /// Box `i` of a row along x (each overlapping its neighbours), jittering with `step`.
    fn row_box(i: u32, step: u32) -> Aabb {
        let wobble = ((i * 7 + step * 13) % 17) as f32 * 0.004;
        let c = Vec3::new(i as f32 * 0.9, wobble, 0.05 - wobble);
        Aabb::from_center_half_extents(c, Vec3::splat(0.5))
    }

    #[test]
    fn a_jittering_row_of_2000_falls_back_and_keeps_the_brute_force_pairs_and_changes() {
        let mut adaptive = AdaptiveSweep::new();
        let mut brute = BruteForce::new();
        let bodies: Vec<_> = (0..2000)
            .map(|i| (i, row_box(i, 0), BodyKind::Dynamic))
            .collect();
        adaptive.insert_bulk(&bodies).unwrap();
        brute.insert_bulk(&bodies).unwrap();
        let mut was_from_scratch = false;
        for step in 1..=(AdaptiveSweep::PROBE_PERIOD + 10) {
            // Body 5 leaves every seventh step and comes back the next, so the changes are
            // never all empty.
            let (leaves, returns) = (step % 7 == 0, step % 7 == 1 && step > 1);
            for i in (0..2000).filter(|&i| i != 5 || !(leaves || returns)) {
                adaptive.update(i, row_box(i, step)).unwrap();
                brute.update(i, row_box(i, step)).unwrap();
            }
            if leaves {
                adaptive.remove(5).unwrap();
                brute.remove(5).unwrap();
            } else if returns {
                adaptive
                    .insert(5, row_box(5, step), BodyKind::Dynamic)
                    .unwrap();
                brute
                    .insert(5, row_box(5, step), BodyKind::Dynamic)
                    .unwrap();
            }
            adaptive.commit();
            brute.commit();
            assert!(same_pairs(adaptive.pairs(), brute.pairs()), "step {step}");
            assert_eq!(adaptive.added(), brute.added(), "step {step}");
            assert_eq!(adaptive.removed(), brute.removed(), "step {step}");
            let from_scratch = adaptive.is_sorting_from_scratch();
            // The recording's `broad_phase/rebuilt_from_scratch` counter reads this.
            assert_eq!(adaptive.stats().rebuilt, from_scratch, "step {step}");
            was_from_scratch |= from_scratch;
        }
        assert!(was_from_scratch && adaptive.fallbacks() >= 1);
    }

    /// A cloud of 24,000 boxes moves into the regions at its first commit, keeps the brute
    /// force answer (a switch reports the old structure's changes, and none of its own), and
    /// goes back to the incremental SAP once fewer than 10,000 are left.
    #[test]
    fn a_cloud_of_24000_moves_into_regions_and_back_below_10000_with_exact_pairs() {
        let at = |i: u32, step: u32| {
            let c = Vec3::new((i % 40) as f32, (i / 40 % 30) as f32, (i / 1200) as f32) * 1.1;
            let c = c + Vec3::new(0.07, -0.05, 0.03) * ((i * 3 + step) % 7) as f32;
            Aabb::from_center_half_extents(c, Vec3::splat(0.5))
        };
        let (mut adaptive, mut reference) = (AdaptiveSweep::new(), SortAndSweep::new());
        let bodies: Vec<_> = (0..24_000)
            .map(|i| (i, at(i, 0), BodyKind::Dynamic))
            .collect();
        adaptive.insert_bulk(&bodies).unwrap();
        reference.insert_bulk(&bodies).unwrap();
        let mut live: u32 = 24_000;
        for step in 1..=12 {
            if step > 6 {
                // Shrink to 9,000 bodies over the last steps.
                let keep = live.saturating_sub(2_500).max(9_000);
                for id in keep..live {
                    adaptive.remove(id).unwrap();
                    reference.remove(id).unwrap();
                }
                live = keep;
            }
            for i in (0..live).step_by(2) {
                adaptive.update(i, at(i, step)).unwrap();
                reference.update(i, at(i, step)).unwrap();
            }
            adaptive.commit();
            reference.commit();
            assert!(
                same_pairs(adaptive.pairs(), reference.pairs()),
                "step {step}"
            );
            assert_eq!(adaptive.added(), reference.added(), "step {step}");
            assert_eq!(adaptive.removed(), reference.removed(), "step {step}");
            assert_eq!(
                adaptive.is_in_regions(),
                live >= 10_000,
                "step {step}, {live} bodies"
            );
        }
    }

    /// A game's schedule may commit twice a step, once with the same boxes again: that commit
    /// must not clear the strikes of the one that did the work.
    #[test]
    fn a_jittering_row_falls_back_within_3_steps_with_an_empty_commit_between_steps() {
        let mut adaptive = AdaptiveSweep::new();
        let bodies: Vec<_> = (0..2000)
            .map(|i| (i, row_box(i, 0), BodyKind::Dynamic))
            .collect();
        adaptive.insert_bulk(&bodies).unwrap();
        adaptive.commit();
        for step in 1..=3 {
            for i in 0..2000 {
                adaptive.update(i, row_box(i, step)).unwrap();
            }
            adaptive.commit();
            // The same boxes again: no move.
            for i in 0..2000 {
                adaptive.update(i, row_box(i, step)).unwrap();
            }
            adaptive.commit();
        }
        assert!(adaptive.is_sorting_from_scratch());
        assert_eq!(adaptive.fallbacks(), 1);
    }

    /// A commit that spends two swap budgets falls back at once (giving up its insertion sort
    /// there) and reports the same pairs and changes, a removal and an insertion among them;
    /// one that spends less waits for a second strike. The swaps, pairs and changes are those
    /// of a bare incremental SAP given the same boxes, at jitters from calm to violent.
    #[test]
    fn a_row_falls_back_at_its_first_commit_iff_it_swapped_twice_the_budget_with_exact_changes() {
        let n = 2000u32;
        let at = |i: u32, amplitude: f32| {
            let wobble = ((i * 7 + 13) % 17) as f32 * amplitude;
            let c = Vec3::new(i as f32 * 0.9, wobble, 0.05 - wobble);
            Aabb::from_center_half_extents(c, Vec3::splat(0.5))
        };
        let budget = AdaptiveSweep::SWAPS_PER_SORT_UNIT * n as f64 * (n as f64).log2();
        let mut outcomes = [false, false];
        for amplitude in [0.0, 1e-4, 3e-4, 1e-3, 4e-3, 0.02] {
            let bodies: Vec<_> = (0..n).map(|i| (i, at(i, 0.0), BodyKind::Dynamic)).collect();
            let mut adaptive = AdaptiveSweep::new();
            let mut bare: IncrementalSap = IncrementalSap::default();
            adaptive.insert_bulk(&bodies).unwrap();
            bare.insert_bulk(&bodies).unwrap();
            adaptive.commit();
            bare.commit();
            for i in 1..n {
                adaptive.update(i, at(i, amplitude)).unwrap();
                bare.update(i, at(i, amplitude)).unwrap();
            }
            let newcomer = at(n / 2, amplitude * 0.5);
            for sweep in [&mut adaptive as &mut dyn BroadPhase, &mut bare] {
                sweep.remove(0).unwrap();
                sweep.insert(n, newcomer, BodyKind::Dynamic).unwrap();
                sweep.commit();
            }
            let spent = bare.stats().endpoint_swaps as f64 / budget;
            let fell_back = adaptive.is_sorting_from_scratch();
            assert_eq!(
                fell_back,
                spent >= 2.0,
                "jitter {amplitude}: {spent} budgets"
            );
            assert!(
                same_pairs(adaptive.pairs(), bare.pairs()),
                "jitter {amplitude}"
            );
            assert_eq!(adaptive.added(), bare.added(), "jitter {amplitude}");
            assert_eq!(adaptive.removed(), bare.removed(), "jitter {amplitude}");
            assert!(!bare.added().is_empty() && !bare.removed().is_empty());
            outcomes[usize::from(fell_back)] = true;
        }
        assert_eq!(outcomes, [true, true], "both outcomes tried");
    }

    /// A cloud of 3,000 boxes shaken hard enough that each commit of a bare SAP swaps more
    /// than the dense count per body (but well under the budget) moves into the regions at its
    /// second commit with the reference's pairs and changes, stays there while it calms until
    /// the probe, and then comes back to the incremental SAP and stays.
    #[test]
    fn a_densely_moving_cloud_of_3000_uses_the_regions_until_it_calms_with_exact_pairs() {
        let n = 3000u32;
        let side = (4.0 * n as f32).cbrt();
        let hash = |i: u32, k: u32| {
            let x =
                (i.wrapping_mul(2_654_435_761) ^ k.wrapping_mul(40_503)).wrapping_mul(747_796_405);
            (x >> 8) as f32 / (1u32 << 24) as f32
        };
        let at = |i: u32, step: u32, jitter: f32| {
            let base = Vec3::new(hash(i, 1), hash(i, 2), hash(i, 3)) * side;
            let shake = Vec3::new(
                hash(i, 3 * step + 4),
                hash(i, 3 * step + 5),
                hash(i, 3 * step + 6),
            );
            Aabb::from_center_half_extents(base + (shake - 0.5) * jitter, Vec3::splat(0.5))
        };
        let bodies: Vec<_> = (0..n)
            .map(|i| (i, at(i, 0, 0.2), BodyKind::Dynamic))
            .collect();
        let (mut adaptive, mut reference) = (AdaptiveSweep::new(), SortAndSweep::new());
        let mut bare: IncrementalSap = IncrementalSap::default();
        for sweep in [
            &mut adaptive as &mut dyn BroadPhase,
            &mut reference,
            &mut bare,
        ] {
            sweep.insert_bulk(&bodies).unwrap();
            sweep.commit();
        }
        let budget = AdaptiveSweep::swap_budget(n as usize);
        let calm_from = 5;
        for step in 1..=calm_from + AdaptiveSweep::PROBE_PERIOD + 5 {
            let jitter = if step < calm_from { 0.2 } else { 0.002 };
            for sweep in [
                &mut adaptive as &mut dyn BroadPhase,
                &mut reference,
                &mut bare,
            ] {
                for i in 0..n {
                    sweep.update(i, at(i, step, jitter)).unwrap();
                }
                sweep.commit();
            }
            assert!(
                same_pairs(adaptive.pairs(), reference.pairs()),
                "step {step}"
            );
            assert_eq!(adaptive.added(), reference.added(), "step {step}");
            assert_eq!(adaptive.removed(), reference.removed(), "step {step}");
            let swaps = bare.stats().endpoint_swaps as f64;
            if step < calm_from {
                let dense = AdaptiveSweep::DENSE_SWAPS_PER_BODY * n as f64;
                assert!(
                    swaps > dense && swaps < 0.8 * budget,
                    "step {step}: {swaps} swaps"
                );
            } else if step > calm_from {
                assert!(swaps < n as f64, "calm step {step}: {swaps} swaps");
            }
            // Switched at step 2's commit; the probe comes PROBE_PERIOD moving commits later.
            let in_regions = (2..2 + AdaptiveSweep::PROBE_PERIOD).contains(&step);
            assert_eq!(adaptive.is_in_regions(), in_regions, "step {step}");
        }
        assert!(!adaptive.is_in_regions() && !adaptive.is_sorting_from_scratch());
        assert_eq!(adaptive.fallbacks(), 0);
    }

    #[test]
    fn a_calm_cloud_stays_incremental() {
        let mut adaptive = AdaptiveSweep::new();
        let at = |i: u32, step: u32| {
            let c = Vec3::new((i % 30) as f32, (i / 30 % 30) as f32, (i / 900) as f32) * 1.2;
            let c = c + Vec3::X * 0.001 * ((i + step) % 5) as f32;
            Aabb::from_center_half_extents(c, Vec3::splat(0.5))
        };
        let bodies: Vec<_> = (0..2700)
            .map(|i| (i, at(i, 0), BodyKind::Dynamic))
            .collect();
        adaptive.insert_bulk(&bodies).unwrap();
        for step in 1..60 {
            for i in 0..2700 {
                adaptive.update(i, at(i, step)).unwrap();
            }
            adaptive.commit();
        }
        assert_eq!(adaptive.fallbacks(), 0);
        assert!(!adaptive.is_sorting_from_scratch());
    }
}

//! How incremental sweep and prune turns per-axis overlap changes into the pair list: two
//! strategies behind one trait, so both can be measured on the same scenes.
//!
//! - [`AxisBits`]: the slides' pair table, one overlap bit per axis, flipped inside the swap;
//!   a pair is listed when all three bits are set. The slides' table is a dense n×n matrix;
//!   here it is sparse (a hash map keyed by pair, an entry alive while any bit is set). Sparse
//!   still means one entry per pair overlapping on *any* axis, and in a scene spread over a
//!   cube of side `L` a body's projection overlaps about `2n/L` others on each axis, so the
//!   table grows like `n^2 / L` (≈ `n^(5/3)` at fixed density) while the listed pairs grow
//!   like `n`.
//! - [`AxisTests`] (Bullet's `btAxisSweep3`, Coumans): no table. When a swap *starts* an
//!   overlap on one axis, test the other two axes directly (by endpoint position) and list the
//!   pair if they overlap too; when a swap *ends* one, unlist the pair if it was listed (it was
//!   iff the other two axes overlap, which the same position test answers without a lookup).
//!   Memory follows the listed pairs only.
//!
//! Both keep the invariant "a non-static–static pair is listed iff, by endpoint position, it
//! overlaps on all three axes" across every single swap, which is why the final list after the
//! arrays are sorted is exactly the set of intersecting boxes.
//!
//! Measured on the bench scenes (`benches/broad_phase.rs`: cube of side `(8n/3)^(1/3)`, box
//! sides uniform in 0.5..1.5, ≈1.4 pairs per body; game-like: 10% of the bodies jitter by up
//! to 0.05 per step; dense cloud: all move 0.05 per step). Release build, CPU time per step on
//! a shared 2-core Xeon, so read the ratios more than the absolute times:
//!
//! | bodies  | heap bytes/body, tests · bits | table entries/body | game-like step | dense-cloud step | bulk build |
//! |--------:|-------------------:|----:|-----------------:|----------------:|------------:|
//! |   1 000 |  271 · 4 700–9 200 | 181 | 0.023 · 0.057 ms | 0.15 · 0.46 ms  | <1 · 8 ms   |
//! |   3 000 |  224 · 12 100      | 393 | 0.088 · 0.46 ms  | 0.57 · 3.7 ms   | 2 · 88 ms   |
//! |  10 000 |  197 · 28 700      | 923 | 0.48 · 5.9 ms    | 2.9 · 40 ms     | 7 · 825 ms  |
//! | 100 000 |  178 · ≈130 000 (≈13 GB by the trend: not run) | — | 21 ms · — | 107 ms · — | 210 ms · — |
//!
//! Both strategies make the same swaps and list the same pairs; the table costs 17–145× the
//! memory and 2.5–14× the time (a hash update on every min/max swap instead of four integer
//! subtractions, in a table that falls out of cache), and its entries per body grow like
//! `n^(2/3)`.
//!
//! [`AxisTests`] is therefore the default.

use super::Pair;
use super::id_marks::IdMarks;
use super::pair_set::PairSet;
use super::positions::{EndpointSlots, Pass, cross_overlap_bit, cross_slots, owner_id};
use crate::pair_hash::{PairMap, hash_map_bytes};
use std::fmt::Debug;

/// A way to keep the pair list in step with endpoint swaps (see the module doc): the type
/// parameter of [`super::IncrementalSap`], implemented by [`AxisTests`] and [`AxisBits`]. Its
/// methods are the broad phase's internals (their argument types are not public), so it
/// cannot be implemented outside this crate.
pub trait PairTracking: Default + Debug {
    /// A short name for benches and reports.
    const NAME: &'static str;

    /// The axes to sweep to find the pairs of newly inserted bodies: one sweep plus
    /// cross-axis tests, or one sweep per axis to set every bit.
    #[doc(hidden)]
    const BULK_AXES: &'static [usize];

    /// Whether the sweep after an insertion should report only the pairs that overlap on the
    /// cross axes too (the only ones the tracking keeps).
    #[doc(hidden)]
    const SWEEP_FILTERS_CROSS_AXES: bool;

    /// An endpoint passed another while an axis was being sorted (most passes change
    /// nothing: see `Pass::flips_overlap`).
    #[doc(hidden)]
    fn endpoint_passed(&mut self, ctx: TrackingContext<'_>, pass: &Pass);

    /// The sweep after an insertion found `a` and `b` (one of them new) overlapping on `axis`;
    /// `on_other_axes` tells whether they overlap on the other two as well.
    #[doc(hidden)]
    fn fresh_overlap(
        &mut self,
        ctx: TrackingContext<'_>,
        axis: usize,
        a: u32,
        b: u32,
        on_other_axes: bool,
    );

    /// Drops every record of the marked bodies (their listed pairs are already unlisted).
    #[doc(hidden)]
    fn forget(&mut self, gone: &IdMarks);

    /// Heap bytes held.
    fn memory_bytes(&self) -> usize;
}

/// What a [`PairTracking`] may read and write while an overlap changes.
pub struct TrackingContext<'a> {
    /// Endpoint positions of every body (current on the axes not being sorted).
    pub slots: &'a [EndpointSlots],
    /// The listed pairs.
    pub pairs: &'a mut PairSet,
}

/// Bullet's strategy: cross-axis tests at the swap, no table (the default).
#[derive(Debug, Default)]
pub struct AxisTests;

impl PairTracking for AxisTests {
    const NAME: &'static str = "axis-tests";
    const BULK_AXES: &'static [usize] = &[0];
    const SWEEP_FILTERS_CROSS_AXES: bool = true;

    #[inline(always)]
    fn endpoint_passed(&mut self, ctx: TrackingContext<'_>, pass: &Pass) {
        // One branch, almost never taken: whether a pass flips an overlap, and whether the
        // bodies overlap on a cross axis, are coin tosses a branch predictor cannot learn.
        let passed_cross = cross_slots(&ctx.slots[owner_id(pass.passed) as usize], pass.axis);
        if pass.flips_overlap_bit() & cross_overlap_bit(&pass.moving_cross, &passed_cross) != 0 {
            let pair = Pair::ordered(owner_id(pass.moving), owner_id(pass.passed));
            if pass.begins() {
                ctx.pairs.add(pair);
            } else {
                let was_listed = ctx.pairs.remove(pair);
                debug_assert!(
                    was_listed,
                    "{pair:?} overlapped on all axes but was not listed"
                );
            }
        }
    }

    #[inline]
    fn fresh_overlap(
        &mut self,
        ctx: TrackingContext<'_>,
        _axis: usize,
        a: u32,
        b: u32,
        on_other_axes: bool,
    ) {
        if on_other_axes {
            ctx.pairs.add(Pair::ordered(a, b));
        }
    }

    fn forget(&mut self, _gone: &IdMarks) {}

    fn memory_bytes(&self) -> usize {
        0
    }
}

/// The slides' strategy: one overlap bit per axis in a sparse pair table.
#[derive(Debug, Default)]
pub struct AxisBits {
    /// Pair key → overlap bits (bit `axis`); entries with no bit set are removed.
    bits: PairMap<u8>,
}

/// All three axis bits.
const ALL_AXES: u8 = 0b111;

impl AxisBits {
    /// Number of pairs overlapping on at least one axis (the table's entries).
    pub fn table_len(&self) -> usize {
        self.bits.len()
    }

    /// The pair's projections began to overlap on `axis`: set the bit, list on all three.
    fn set_bit(&mut self, ctx: TrackingContext<'_>, axis: usize, pair: Pair) {
        let bits = self.bits.entry(pair.key()).or_insert(0);
        *bits |= 1 << axis;
        if *bits == ALL_AXES {
            ctx.pairs.add(pair);
        }
    }

    /// The pair's projections stopped overlapping on `axis`: unlist it if it was listed,
    /// clear the bit, drop the entry when no bit is left.
    fn clear_bit(&mut self, ctx: TrackingContext<'_>, axis: usize, pair: Pair) {
        let key = pair.key();
        let Some(bits) = self.bits.get_mut(&key) else {
            debug_assert!(false, "{pair:?} stopped overlapping but had no bits");
            return;
        };
        if *bits == ALL_AXES {
            ctx.pairs.remove(pair);
        }
        *bits &= !(1 << axis);
        if *bits == 0 {
            self.bits.remove(&key);
        }
    }
}

impl PairTracking for AxisBits {
    const NAME: &'static str = "axis-bits";
    const BULK_AXES: &'static [usize] = &[0, 1, 2];
    const SWEEP_FILTERS_CROSS_AXES: bool = false;

    #[inline(always)]
    fn endpoint_passed(&mut self, ctx: TrackingContext<'_>, pass: &Pass) {
        if pass.flips_overlap() {
            let pair = Pair::ordered(owner_id(pass.moving), owner_id(pass.passed));
            if pass.begins() {
                self.set_bit(ctx, pass.axis, pair);
            } else {
                self.clear_bit(ctx, pass.axis, pair);
            }
        }
    }

    #[inline]
    fn fresh_overlap(
        &mut self,
        ctx: TrackingContext<'_>,
        axis: usize,
        a: u32,
        b: u32,
        _on_other_axes: bool,
    ) {
        self.set_bit(ctx, axis, Pair::ordered(a, b));
    }

    fn forget(&mut self, gone: &IdMarks) {
        // Only the table's content changes; its iteration order reaches no output.
        self.bits.retain(|&key, _| {
            let pair = Pair::from_key(key);
            !gone.get(pair.a) && !gone.get(pair.b)
        });
    }

    fn memory_bytes(&self) -> usize {
        hash_map_bytes(&self.bits)
    }
}

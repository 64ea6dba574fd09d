//! Tests of [`AdaptiveSweep`](super::AdaptiveSweep): its fallbacks, regions and probes against
//! reference broad phases.

use super::*;
use crate::broad_phase::BruteForce;
use glam::Vec3;

/// Box `i` of a row along x (each overlapping its neighbours), jittering with `step`.
fn row_box(i: u32, step: u32) -> Aabb {
    let wobble = ((i * 7 + step * 13) % 17) as f32 * 0.004;
    let c = Vec3::new(i as f32 * 0.9, wobble, 0.05 - wobble);
    Aabb::from_center_half_extents(c, Vec3::splat(0.5))
}

/// The pairs of `a` and `b` as sorted sets are equal (the structures list pairs in different
/// orders).
fn same_pairs(a: &[Pair], b: &[Pair]) -> bool {
    let mut a = a.to_vec();
    a.sort_unstable();
    let (added, removed) = changes_since(&a, b);
    added.is_empty() && removed.is_empty()
}

/// Inserts `n` dynamic boxes, box `i` at `at(i)`, into each of `sweeps`.
fn fill<const K: usize>(n: u32, at: impl Fn(u32) -> Aabb, sweeps: [&mut dyn BroadPhase; K]) {
    let bodies: Vec<_> = (0..n).map(|i| (i, at(i), BodyKind::Dynamic)).collect();
    for sweep in sweeps {
        sweep.insert_bulk(&bodies).unwrap();
    }
}

/// Asserts that `got` reports the same pairs (in any order) and the same changes as `want`;
/// `context` names the step or case in the failure message.
fn assert_same_pairs_and_changes(
    got: &dyn BroadPhase,
    want: &dyn BroadPhase,
    context: impl std::fmt::Display,
) {
    assert!(same_pairs(got.pairs(), want.pairs()), "{context}");
    assert_eq!(got.added(), want.added(), "{context}");
    assert_eq!(got.removed(), want.removed(), "{context}");
}

#[test]
fn a_jittering_row_of_2000_falls_back_and_keeps_the_brute_force_pairs_and_changes() {
    let mut adaptive = AdaptiveSweep::new();
    let mut brute = BruteForce::new();
    fill(2000, |i| row_box(i, 0), [&mut adaptive, &mut brute]);
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
        assert_same_pairs_and_changes(&adaptive, &brute, format_args!("step {step}"));
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
    fill(24_000, |i| at(i, 0), [&mut adaptive, &mut reference]);
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
        assert_same_pairs_and_changes(&adaptive, &reference, format_args!("step {step}"));
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
    fill(2000, |i| row_box(i, 0), [&mut adaptive]);
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
        let mut adaptive = AdaptiveSweep::new();
        let mut bare: IncrementalSap = IncrementalSap::default();
        fill(n, |i| at(i, 0.0), [&mut adaptive, &mut bare]);
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
        assert_same_pairs_and_changes(&adaptive, &bare, format_args!("jitter {amplitude}"));
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
        let x = (i.wrapping_mul(2_654_435_761) ^ k.wrapping_mul(40_503)).wrapping_mul(747_796_405);
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
    let (mut adaptive, mut reference) = (AdaptiveSweep::new(), SortAndSweep::new());
    let mut bare: IncrementalSap = IncrementalSap::default();
    fill(
        n,
        |i| at(i, 0, 0.2),
        [&mut adaptive, &mut reference, &mut bare],
    );
    for sweep in [
        &mut adaptive as &mut dyn BroadPhase,
        &mut reference,
        &mut bare,
    ] {
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
        assert_same_pairs_and_changes(&adaptive, &reference, format_args!("step {step}"));
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
    fill(2700, |i| at(i, 0), [&mut adaptive]);
    for step in 1..60 {
        for i in 0..2700 {
            adaptive.update(i, at(i, step)).unwrap();
        }
        adaptive.commit();
    }
    assert_eq!(adaptive.fallbacks(), 0);
    assert!(!adaptive.is_sorting_from_scratch());
}

/// A 40 × 40 net of boxes in one vertical plane (the joint grid's shape), jumping up to 3 m a
/// step: insertion sort loses and the bodies sort from scratch, where every column of 40
/// shares its interval on the sweep axis (about 30 box tests per body that find nothing);
/// after two such commits they move into the regions (a quarter of the tests there). The
/// pairs and changes stay the brute force's throughout.
#[test]
fn a_jumping_net_of_1600_leaves_the_sort_from_scratch_for_the_regions_with_exact_pairs() {
    let at = |i: u32, step: u32| {
        let (column, row) = ((i / 40) as f32, (i % 40) as f32);
        let jump = ((i * 7 + step * 5 + i * step) % 61) as f32 * 0.1 - 3.0;
        let c = Vec3::new(column, 0.0, row + jump);
        Aabb::from_center_half_extents(c, Vec3::splat(0.4))
    };
    let (mut adaptive, mut brute) = (AdaptiveSweep::new(), BruteForce::new());
    fill(1600, |i| at(i, 0), [&mut adaptive, &mut brute]);
    let (mut was_from_scratch, mut dense_sweeps) = (false, 0);
    for step in 1..=12 {
        for i in 0..1600 {
            adaptive.update(i, at(i, step)).unwrap();
            brute.update(i, at(i, step)).unwrap();
        }
        adaptive.commit();
        brute.commit();
        assert_same_pairs_and_changes(&adaptive, &brute, format_args!("step {step}"));
        if adaptive.is_sorting_from_scratch() {
            was_from_scratch = true;
            let idle = adaptive.stats().pair_tests as f64 - adaptive.pairs().len() as f64;
            dense_sweeps += usize::from(idle > AdaptiveSweep::DENSE_TESTS_PER_BODY * 1600.0);
        }
    }
    assert!(was_from_scratch && adaptive.fallbacks() == 1);
    assert!(dense_sweeps >= 1, "the sweeps from scratch were crowded");
    assert!(adaptive.is_in_regions());
}

//! The segmented sweep and prune ([`RegionSweep`], issue 12) on scenes the random call
//! sequences of `broad_phase_props` are too small for: thousands of bodies of mixed sizes with
//! large ones among them, cells tuned while bodies move, a row along one axis, coincident and
//! far-away boxes; pairs, additions and removals must equal an independent broad phase's after
//! every commit. And no allocation per step once its buffers have grown.

use super::broad_phase_props::{steady_state_allocations, swinging_box};
use crate::common::rng::Rng;
use glam::Vec3;
use urto::bounding::Aabb;
use urto::broad_phase::{
    BodyKind, BroadPhase, BruteForce, Pair, ProxyId, RegionSweep, SortAndSweep,
};

/// Commits both and asserts the same pairs, additions and removals.
fn commit_and_compare(subject: &mut RegionSweep, reference: &mut dyn BroadPhase, step: usize) {
    subject.commit();
    reference.commit();
    let (mut expected, mut got) = (Vec::new(), Vec::new());
    reference.sorted_pairs_into(&mut expected);
    subject.sorted_pairs_into(&mut got);
    assert_eq!(got, expected, "pairs at step {step}");
    assert_eq!(subject.added(), reference.added(), "added at step {step}");
    assert_eq!(
        subject.removed(),
        reference.removed(),
        "removed at step {step}"
    );
}

/// Static for one id in `n`, dynamic otherwise.
fn static_one_in(i: u32, n: u32) -> BodyKind {
    if i.is_multiple_of(n) {
        BodyKind::Static
    } else {
        BodyKind::Dynamic
    }
}

/// Both broad phases holding `bodies`, committed once and compared.
fn started(bodies: &[(ProxyId, Aabb, BodyKind)]) -> (RegionSweep, SortAndSweep) {
    let (mut subject, mut reference) = (RegionSweep::new(), SortAndSweep::new());
    for bp in both(&mut subject, &mut reference) {
        bp.insert_bulk(bodies).unwrap();
    }
    commit_and_compare(&mut subject, &mut reference, 0);
    (subject, reference)
}

/// Moves body `i` in both by a random step of up to `speed` along each axis.
fn shake(
    i: ProxyId,
    speed: f32,
    rng: &mut Rng,
    subject: &mut RegionSweep,
    reference: &mut SortAndSweep,
) {
    let b = reference.aabb(i).unwrap();
    let d = rng.vec3(-speed, speed);
    for bp in both(subject, reference) {
        bp.update(i, Aabb::new(b.min + d, b.max + d)).unwrap();
    }
}

fn both<'a>(
    subject: &'a mut RegionSweep,
    reference: &'a mut SortAndSweep,
) -> [&'a mut dyn BroadPhase; 2] {
    [subject, reference]
}

/// 3,000 boxes of sizes 0.2–2 in a 30 m cube (one in twenty static), a static ground slab and
/// wall and a moving slab (each far more cells than a region takes); a third jitter each step,
/// every twentieth step they jump, and some leave and come back.
#[test]
fn mixed_sizes_with_large_bodies_match_sort_and_sweep_exactly_for_120_steps() {
    let mut rng = Rng::new(0x5eed_0f7e_5700);
    let mut bodies: Vec<(ProxyId, Aabb, BodyKind)> = (0..3000)
        .map(|i| {
            let c = rng.vec3(0.0, 30.0);
            let half = rng.vec3(0.1, 1.0);
            let kind = static_one_in(i, 20);
            (i, Aabb::from_center_half_extents(c, half), kind)
        })
        .collect();
    let ground = Aabb::new(Vec3::new(-50.0, -1.0, -50.0), Vec3::new(80.0, 0.5, 80.0));
    let wall = Aabb::new(Vec3::new(14.0, 0.0, -5.0), Vec3::new(15.0, 35.0, 35.0));
    bodies.push((3000, ground, BodyKind::Static));
    bodies.push((3001, wall, BodyKind::Static));
    let slab = |t: f32| Aabb::new(Vec3::new(-5.0, t, -5.0), Vec3::new(35.0, t + 0.5, 35.0));
    bodies.push((3002, slab(0.0), BodyKind::Dynamic));
    let (mut subject, mut reference) = started(&bodies);
    for step in 1..=120usize {
        let speed = if step % 20 == 0 { 3.0 } else { 0.1 };
        for i in (0..3000u32).filter(|i| (*i as usize + step).is_multiple_of(3)) {
            shake(i, speed, &mut rng, &mut subject, &mut reference);
        }
        for bp in both(&mut subject, &mut reference) {
            bp.update(3002, slab(step as f32 * 0.25)).unwrap();
            let leaving = (step * 37 % 3000) as ProxyId;
            let kept = bp.aabb(leaving).unwrap();
            bp.remove(leaving).unwrap();
            if step % 2 == 0 {
                bp.insert(leaving, kept, BodyKind::Dynamic).unwrap();
            } else {
                bp.insert(
                    leaving,
                    Aabb::new(kept.min + 5.0, kept.max + 5.0),
                    BodyKind::Static,
                )
                .unwrap();
            }
        }
        commit_and_compare(&mut subject, &mut reference, step);
    }
    assert!(subject.pairs().len() > 1000, "{}", subject.pairs().len());
    assert!(subject.region_count() > 8, "{}", subject.region_count());
}

/// 4,000 boxes in a dense 25 m cube, one in fifty a rod 5 m long along a random axis (so a
/// region's longest member bounds its backward sweep), and only 1 % moving each step (a few
/// jumping): the regions sweep just their changed members and keep the other pairs.
#[test]
fn few_movers_among_many_match_sort_and_sweep_exactly_for_100_steps() {
    let mut rng = Rng::new(0xfe00_5eed);
    let bodies: Vec<(ProxyId, Aabb, BodyKind)> = (0..4000)
        .map(|i| {
            let c = rng.vec3(0.0, 25.0);
            let mut half = Vec3::splat(rng.range(0.2, 0.6));
            if i % 50 == 0 {
                half[(i / 50 % 3) as usize] = 2.5;
            }
            let kind = static_one_in(i, 7);
            (i, Aabb::from_center_half_extents(c, half), kind)
        })
        .collect();
    let (mut subject, mut reference) = started(&bodies);
    for step in 1..=100usize {
        for k in 0..40u32 {
            let i = (k * 97 + step as u32 * 13) % 4000;
            let speed = if k % 10 == 0 { 4.0 } else { 0.15 };
            shake(i, speed, &mut rng, &mut subject, &mut reference);
        }
        commit_and_compare(&mut subject, &mut reference, step);
    }
    assert!(subject.pairs().len() > 2000, "{}", subject.pairs().len());
}

/// 1,000 unit boxes spread through a 200 m cube: four box sizes per cell leaves a region with
/// about one body, so the cells grow until a region holds at least `SPARSE_REGION` or the
/// tuning rounds run out; the pairs stay exact throughout.
#[test]
fn a_sparse_cloud_grows_its_cells_at_least_4_fold_and_stays_exact() {
    let mut rng = Rng::new(0xa115_9a45);
    let (mut subject, mut reference) = (RegionSweep::new(), SortAndSweep::new());
    let boxes: Vec<Aabb> = (0..1000)
        .map(|_| {
            let c = rng.vec3(0.0, 200.0);
            Aabb::from_center_half_extents(c, Vec3::splat(0.5))
        })
        .collect();
    for (i, b) in boxes.iter().enumerate() {
        for bp in both(&mut subject, &mut reference) {
            bp.insert(i as ProxyId, *b, BodyKind::Dynamic).unwrap();
        }
    }
    commit_and_compare(&mut subject, &mut reference, 0);
    let first = subject.cell_size().unwrap();
    for step in 1..=20 {
        for (i, b) in boxes.iter().enumerate() {
            let d = Vec3::splat(0.05 * step as f32);
            for bp in both(&mut subject, &mut reference) {
                bp.update(i as ProxyId, Aabb::new(b.min + d, b.max + d))
                    .unwrap();
            }
        }
        commit_and_compare(&mut subject, &mut reference, step);
    }
    let last = subject.cell_size().unwrap();
    assert!(last >= 4.0 * first, "cells {first} -> {last}");
    assert!(subject.layouts() >= 3, "{}", subject.layouts());
}

/// 5,000 unit boxes in a row along x, all jittering (the incremental SAP's worst case: every
/// box's y and z intervals overlap every other's).
#[test]
fn a_row_of_5000_boxes_along_x_matches_sort_and_sweep_for_30_steps() {
    let mut rng = Rng::new(0x05ee_d0f0);
    let (mut subject, mut reference) = (RegionSweep::new(), SortAndSweep::new());
    let row = |i: u32, d: Vec3| {
        Aabb::from_center_half_extents(Vec3::new(i as f32 * 0.9, 0.0, 0.0) + d, Vec3::splat(0.5))
    };
    for bp in both(&mut subject, &mut reference) {
        let bodies: Vec<_> = (0..5000)
            .map(|i| (i, row(i, Vec3::ZERO), BodyKind::Dynamic))
            .collect();
        bp.insert_bulk(&bodies).unwrap();
    }
    commit_and_compare(&mut subject, &mut reference, 0);
    for step in 1..=30 {
        for i in 0..5000 {
            let d = Vec3::new(
                rng.range(-0.05, 0.05),
                rng.range(-0.2, 0.2),
                rng.range(-0.2, 0.2),
            );
            for bp in both(&mut subject, &mut reference) {
                bp.update(i, row(i, d)).unwrap();
            }
        }
        commit_and_compare(&mut subject, &mut reference, step);
    }
    assert!(subject.pairs().len() > 4000, "{}", subject.pairs().len());
}

/// Hostile shapes of scene: 300 zero-size boxes on one point, boxes near ±1e30 (their cells
/// saturate the integer range), one box spanning all of f32, tiny and huge boxes mixed.
#[test]
fn coincident_points_far_boxes_and_an_all_space_box_match_brute_force() {
    let mut subject = RegionSweep::new();
    let mut reference = BruteForce::new();
    let mut bodies: Vec<(ProxyId, Aabb, BodyKind)> = (0..300)
        .map(|i| {
            (
                i,
                Aabb::new(Vec3::splat(1.0), Vec3::splat(1.0)),
                BodyKind::Dynamic,
            )
        })
        .collect();
    for (k, at) in [1e30f32, -1e30, 3e30, f32::MAX].into_iter().enumerate() {
        let c = Vec3::new(at, 0.0, 0.0);
        bodies.push((
            300 + k as ProxyId,
            Aabb::new(c - 1e25, c),
            BodyKind::Dynamic,
        ));
    }
    bodies.push((
        310,
        Aabb::new(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX)),
        BodyKind::Static,
    ));
    bodies.push((
        311,
        Aabb::new(Vec3::splat(0.5), Vec3::splat(0.5 + 1e-30)),
        BodyKind::Dynamic,
    ));
    bodies.push((
        312,
        Aabb::new(Vec3::splat(-1e6), Vec3::splat(1e6)),
        BodyKind::Dynamic,
    ));
    for bp in [&mut subject as &mut dyn BroadPhase, &mut reference] {
        bp.insert_bulk(&bodies).unwrap();
    }
    for step in 0..8 {
        for bp in [&mut subject as &mut dyn BroadPhase, &mut reference] {
            let x = step as f32 * 0.3;
            bp.update(311, Aabb::new(Vec3::splat(x), Vec3::splat(x + 1e-30)))
                .unwrap();
            bp.update(
                303,
                Aabb::new(Vec3::new(f32::MAX, -1.0, -1.0), Vec3::splat(f32::MAX)),
            )
            .unwrap();
            bp.commit();
        }
        let (mut expected, mut got) = (Vec::new(), Vec::new());
        reference.sorted_pairs_into(&mut expected);
        subject.sorted_pairs_into(&mut got);
        assert_eq!(got, expected, "step {step}");
        assert_eq!(subject.added(), reference.added());
        assert_eq!(subject.removed(), reference.removed());
    }
    assert!(subject.pairs().contains(&Pair { a: 0, b: 1 }));
}

#[test]
fn region_sweep_makes_0_allocations_per_step_once_its_buffers_have_grown() {
    // The phase taken modulo the period, so the motion repeats bit for bit: without it,
    // rounding lets a box near a cell's edge enter a new cell late. Freed regions are reused in
    // a different order from one period to the next, so their buffers take a few periods to
    // all reach what any cell needs.
    let (made, churn) =
        steady_state_allocations(&mut RegionSweep::new(), |i, n| swinging_box(i, n % 60));
    assert!(
        churn > 1000,
        "the scene must start and end overlaps: {churn}"
    );
    assert_eq!(made, 0, "{made} allocations in 120 steady steps");
}

/// 3,000 small boxes packed in a 16 m cube (seven a region at four median sizes a cell: not
/// sparse) and 40 boxes twenty times their size, each over 200 of those cells: past `16 + n /
/// 128` large bodies the cells grow (here to twice their side, where the big ones span at most
/// 64), and the pairs stay exact.
#[test]
fn forty_big_boxes_among_small_ones_grow_the_cells_until_few_are_large_and_stay_exact() {
    let mut rng = Rng::new(0xb16_5a11);
    let bodies: Vec<(ProxyId, Aabb, BodyKind)> = (0..3040)
        .map(|i| {
            let c = rng.vec3(0.0, 16.0);
            let half = if i < 3000 { 0.25 } else { rng.range(5.0, 6.0) };
            (
                i,
                Aabb::from_center_half_extents(c, Vec3::splat(half)),
                BodyKind::Dynamic,
            )
        })
        .collect();
    let (mut subject, mut reference) = started(&bodies);
    let first = subject.cell_size().unwrap();
    for step in 1..=12usize {
        for i in (0..3040u32).step_by(3) {
            let b = reference.aabb(i).unwrap();
            let d = Vec3::splat(0.1 * (step % 3) as f32 - 0.1);
            for bp in both(&mut subject, &mut reference) {
                bp.update(i, Aabb::new(b.min + d, b.max + d)).unwrap();
            }
        }
        commit_and_compare(&mut subject, &mut reference, step);
    }
    let last = subject.cell_size().unwrap();
    assert!(last >= 2.0 * first, "cells {first} -> {last}");
    assert!(
        subject.large_bodies() <= 16 + 4000 / 128,
        "{}",
        subject.large_bodies()
    );
}

/// The review's case: a member spanning x from 0.1 to 1.0, whose length `1.0 - 0.1` rounds
/// below the true one, touched at x = 1.0 by the one member that moved. The backward walk of
/// the partial sweep must still reach it.
#[test]
fn a_pair_touching_at_a_rounded_length_is_found_by_the_partial_sweep() {
    let span = |x0: f32, x1: f32| Aabb::new(Vec3::new(x0, 0.0, 0.0), Vec3::new(x1, 0.5, 0.5));
    let (mut subject, mut reference) = (RegionSweep::new(), BruteForce::new());
    let start = [
        (0.1, 1.0),
        (1.05, 1.45),
        (1.5, 1.9),
        (1.6, 1.9),
        (1.7, 1.95),
    ];
    for (id, (x0, x1)) in start.into_iter().enumerate() {
        for bp in [&mut subject as &mut dyn BroadPhase, &mut reference] {
            bp.insert(id as ProxyId, span(x0, x1), BodyKind::Dynamic)
                .unwrap();
        }
    }
    for bp in [&mut subject as &mut dyn BroadPhase, &mut reference] {
        bp.commit();
        bp.update(1, span(1.0, 1.4)).unwrap();
        bp.commit();
    }
    let (mut expected, mut got) = (Vec::new(), Vec::new());
    reference.sorted_pairs_into(&mut expected);
    subject.sorted_pairs_into(&mut got);
    assert!(expected.contains(&Pair { a: 0, b: 1 }));
    assert_eq!(got, expected);
    assert_eq!(subject.added(), reference.added());
}

//! The index's kept groups: colliders split between the group re-read at every update and the
//! two re-read only when asked (still and sleeping) answer every query as one index over all of
//! them, and a still group left alone keeps answering with the poses it was given.

use super::{indexed, random_ray, scene};
use crate::common::rng::Rng;
use urto::geometry::{Capsule, Isometry, Shape};
use urto::spatial::{BoxCast, CapsuleCast, IndexUpdate, SpatialIndex};

/// The index with each collider in the group `group_of` names (0 moving, 1 still, 2
/// sleeping); ids are the colliders' positions in the slice, as [`indexed`] gives them.
fn split(colliders: &[(Shape, Isometry)], group_of: impl Fn(usize) -> usize) -> SpatialIndex {
    let mut index = SpatialIndex::default();
    let group = |g: usize| {
        let group_of = &group_of;
        colliders
            .iter()
            .enumerate()
            .filter(move |(i, _)| group_of(*i) == g)
            .map(|(i, (s, p))| (i as u32, s, *p))
    };
    index.update(group(0));
    index.update_still(group(1));
    index.update_sleeping(group(2));
    index
}

/// Every query kind on `rounds` random queries gives the same answers (same ids, same bits)
/// from `a` and from `b`.
fn same_answers(
    rng: &mut Rng,
    colliders: &[(Shape, Isometry)],
    (a, b): (&mut SpatialIndex, &mut SpatialIndex),
    rounds: usize,
) -> usize {
    let (mut all_a, mut all_b, mut found) = (Vec::new(), Vec::new(), 0);
    for k in 0..rounds {
        let ray = random_ray(rng);
        let max = if k % 3 == 0 { f32::INFINITY } else { 35.0 };
        let odd = |id: u32| id % 2 == 1;
        let first = a.cast_ray(colliders, &ray, max, odd).unwrap();
        assert_eq!(first, b.cast_ray(colliders, &ray, max, odd).unwrap());
        found += usize::from(first.is_some());
        a.cast_ray_all(colliders, &ray, max, |_| true, &mut all_a)
            .unwrap();
        b.cast_ray_all(colliders, &ray, max, |_| true, &mut all_b)
            .unwrap();
        assert_eq!(all_a, all_b, "ray {k}");
        let r = 0.3;
        let sphere = a.cast_sphere(colliders, &ray, r, max, |_| true).unwrap();
        assert_eq!(
            sphere,
            b.cast_sphere(colliders, &ray, r, max, |_| true).unwrap()
        );
        let cast = BoxCast {
            pose: Isometry::new(ray.origin(), rng.rotation()),
            half_extents: glam::Vec3::new(0.4, 0.7, 0.2),
            direction: ray.direction(),
            max_distance: 40.0,
        };
        let boxed = a.cast_box(colliders, &cast, |_| true).unwrap();
        assert_eq!(boxed, b.cast_box(colliders, &cast, |_| true).unwrap());
        let capsule = CapsuleCast {
            pose: cast.pose,
            capsule: Capsule {
                half_length: 0.5,
                radius: 0.2,
            },
            direction: cast.direction,
            max_distance: 40.0,
        };
        let capsuled = a.cast_capsule(colliders, &capsule, |_| true).unwrap();
        assert_eq!(
            capsuled,
            b.cast_capsule(colliders, &capsule, |_| true).unwrap()
        );
        let at = Isometry::new(rng.in_ball(22.0), rng.rotation());
        let shape = Shape::cuboid(glam::Vec3::new(2.0, 1.0, 3.0));
        let (mut over_a, mut over_b) = (Vec::new(), Vec::new());
        a.overlapping(colliders, (&shape, &at), |_| true, &mut over_a);
        b.overlapping(colliders, (&shape, &at), |_| true, &mut over_b);
        assert_eq!(over_a, over_b, "overlap {k}");
        let p = rng.in_ball(28.0);
        let near_max = if k % 5 == 0 { 1.0 } else { f32::INFINITY };
        let near = a.nearest(colliders, p, near_max, |_| true).unwrap();
        assert_eq!(near, b.nearest(colliders, p, near_max, |_| true).unwrap());
    }
    found
}

#[test]
fn a_split_index_answers_as_one_index_on_400_queries_of_each_kind_over_302_colliders() {
    let mut rng = Rng::new(41);
    let colliders = scene(&mut rng, 300);
    let mut one = indexed(&colliders);
    // Half-spaces in two groups, meshes too: a third of the colliders in each group, one wall
    // still and the other sleeping.
    let mut thirds = split(&colliders, |i| match i {
        300 => 1,
        301 => 2,
        _ => i % 3,
    });
    assert_eq!(thirds.len(), one.len());
    let found = same_answers(&mut rng, &colliders, (&mut thirds, &mut one), 400);
    assert!(found > 100, "{found} rays hit");
    // All in one group, whichever: the same answers too.
    let mut moving = split(&colliders, |_| 0);
    let mut still = split(&colliders, |_| 1);
    let mut sleeping = split(&colliders, |_| 2);
    same_answers(&mut rng, &colliders, (&mut moving, &mut still), 100);
    same_answers(&mut rng, &colliders, (&mut still, &mut one), 100);
    same_answers(&mut rng, &colliders, (&mut sleeping, &mut one), 100);
}

#[test]
fn a_still_group_keeps_its_poses_through_40_moving_updates_until_it_is_updated() {
    let mut rng = Rng::new(42);
    let mut colliders = scene(&mut rng, 200);
    let is_still = |i: usize| i.is_multiple_of(2);
    let mut index = split(&colliders, |i| usize::from(is_still(i)));
    let first_poses = colliders.clone();
    for round in 0..40 {
        for (_, pose) in colliders.iter_mut() {
            pose.translation += rng.in_ball(0.4);
        }
        let moving = colliders
            .iter()
            .enumerate()
            .filter(|(i, _)| !is_still(*i))
            .map(|(i, (s, p))| (i as u32, s, *p));
        assert_eq!(index.update(moving), IndexUpdate::Refitted, "round {round}");
        // The still colliders as the index holds them: where they were at its last update.
        let seen: Vec<(Shape, Isometry)> = colliders
            .iter()
            .zip(&first_poses)
            .enumerate()
            .map(|(i, (now, then))| if is_still(i) { then } else { now }.clone())
            .collect();
        let mut expected = indexed(&seen);
        same_answers(&mut rng, &seen, (&mut index, &mut expected), 10);
    }
    // Updated, the still group follows them; a few gone, the tree is kept.
    let kept = colliders
        .iter()
        .enumerate()
        .filter(|(i, _)| is_still(*i) && *i != 10 && *i != 20)
        .map(|(i, (s, p))| (i as u32, s, *p));
    assert_eq!(index.update_still(kept), IndexUpdate::Updated);
    let mut expected = SpatialIndex::default();
    let gone = |i: usize| i == 10 || i == 20;
    expected.update(
        colliders
            .iter()
            .enumerate()
            .filter(|(i, _)| !gone(*i))
            .map(|(i, (s, p))| (i as u32, s, *p)),
    );
    same_answers(&mut rng, &colliders, (&mut index, &mut expected), 50);
}

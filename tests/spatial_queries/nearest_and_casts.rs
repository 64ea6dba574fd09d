//! Nearest-point queries and box and capsule casts against brute force and parry3d.

use super::*;

#[test]
fn nearest_distances_agree_with_parrys_projections_within_1e_5_on_2500_points_at_five_shapes() {
    use urto::spatial::nearest_point;
    let mut rng = Rng::new(21);
    let shapes = shapes_with_parry_twins();
    let mut scratch = QueryScratch::new();
    for (shape, parry_shape, solid) in &shapes {
        let (mut inside, mut outside) = (0, 0);
        for _ in 0..500 {
            let pose = Isometry::new(rng.in_ball(3.0), rng.rotation());
            let p = pose.translation + rng.in_ball(1.6);
            let ours = nearest_point(shape, &pose, p, &mut scratch);
            let at = parry3d::math::Pose::from_parts(pose.translation, pose.rotation);
            let theirs = parry_shape.project_point(&at, p, *solid);
            let point = Vec3::from_array(theirs.point.to_array());
            assert_eq!(
                ours.inside, theirs.is_inside,
                "{shape:?} {p}: {ours:?} vs {theirs:?}"
            );
            // The distances agree tightly; the points a little less where the nearest point
            // slides along a nearly flat stretch of a mesh (the distance is flat there).
            let context = format!("{shape:?} {p}: {ours:?} vs {point}");
            assert!(
                (ours.distance - p.distance(point)).abs() < 1e-5 * (1.0 + ours.distance),
                "{context}"
            );
            assert!((ours.point - point).length() < 1e-3, "{context}");
            assert!((ours.distance - p.distance(ours.point)).abs() < 1e-5);
            if ours.inside {
                inside += 1;
            } else {
                outside += 1;
            }
        }
        assert!(outside > 100, "{shape:?}: {outside} outside");
        assert!(!solid || inside > 20, "{shape:?}: {inside} inside");
    }
}

#[test]
fn nearest_colliders_equal_brute_force_on_500_points_over_402_colliders() {
    use urto::spatial::nearest_point;
    let mut rng = Rng::new(22);
    let colliders = scene(&mut rng, 400);
    let mut index = indexed(&colliders);
    let mut scratch = QueryScratch::new();
    let mut limited = 0;
    for k in 0..500 {
        let p = rng.in_ball(28.0);
        let max = if k % 5 == 0 { 1.0 } else { f32::INFINITY };
        let brute = colliders
            .iter()
            .enumerate()
            .map(|(i, (s, pose))| (i as u32, nearest_point(s, pose, p, &mut scratch)))
            .filter(|(_, h)| h.distance <= max)
            .min_by(|a, b| a.1.distance.total_cmp(&b.1.distance).then(a.0.cmp(&b.0)));
        let ours = index.nearest(&*colliders, p, max, |_| true).unwrap();
        assert_eq!(ours.map(|o| o.0), brute.map(|b| b.0), "point {k} {p}");
        if let (Some(o), Some(b)) = (ours, brute) {
            assert_eq!(o.1, b.1);
        }
        limited += usize::from(max < 1e3 && ours.is_none());
    }
    assert!(limited > 10, "{limited} queries found nothing within 1 m");
    assert!(
        index
            .nearest(&*colliders, Vec3::NAN, 1.0, |_| true)
            .is_err()
    );
    assert!(
        index
            .nearest(&*colliders, Vec3::ZERO, -1.0, |_| true)
            .is_err()
    );
}

/// parry3d's first hit of `caster` at `pose` moved along the unit `direction` for at most 12 m
/// against `target` at `at`, stopping at penetration (as our casts do).
pub(super) fn parry_cast(
    (caster, pose): (&dyn parry3d::shape::Shape, &Isometry),
    direction: Vec3,
    (target, at): (&dyn parry3d::shape::Shape, &Isometry),
) -> Option<parry3d::query::ShapeCastHit> {
    use parry3d::math::{Pose, Vector};
    let pose_of = |p: &Isometry| Pose::from_parts(p.translation, p.rotation);
    let options = parry3d::query::ShapeCastOptions {
        max_time_of_impact: 12.0,
        stop_at_penetration: true,
        ..Default::default()
    };
    parry3d::query::cast_shapes(
        &pose_of(pose),
        Vector::from_array(direction.to_array()),
        caster,
        &pose_of(at),
        Vector::ZERO,
        target,
        options,
    )
    .expect("supported")
}

#[test]
fn box_casts_touch_within_1e_4_and_agree_with_parry3d_within_1e_3_of_gap_on_2500_casts_at_five_shapes()
 {
    use urto::spatial::{BoxCast, cast_box};
    let mut rng = Rng::new(23);
    let shapes = shapes_with_parry_twins();
    let mut scratch = QueryScratch::new();
    for (shape, parry_shape, _) in &shapes {
        let (mut hits, mut misses, mut worst) = (0, 0, 0.0f32);
        for _ in 0..500 {
            let (target, aimed) = random_target_and_cast(&mut rng);
            let Some((start, direction)) = aimed else {
                continue;
            };
            let cast = BoxCast {
                pose: Isometry::new(start, rng.rotation()),
                half_extents: Vec3::new(rng.range(0.1, 0.6), rng.range(0.1, 0.6), 0.3),
                direction,
                max_distance: 12.0,
            };
            let ours = cast_box(&cast, shape, &target, &mut scratch);
            let caster = parry3d::shape::Cuboid::new(cast.half_extents);
            let theirs = parry_cast(
                (&caster, &cast.pose),
                direction,
                (parry_shape.as_ref(), &target),
            );
            let context = format!("{shape:?} {cast:?} {target:?}: {ours:?} vs {theirs:?}");
            match (ours, theirs) {
                (Some(h), Some(t)) => {
                    // The gap the travel between the two hits closes: at a glancing approach
                    // a gap within the tolerances spans a longer travel.
                    let closing = h.normal.dot(direction).abs();
                    let error = (h.distance - t.time_of_impact).abs() * closing;
                    assert!(error < 1e-3, "{context}");
                    worst = worst.max(error);
                    // Independently of parry: touching at our distance, apart 1e-4 before it.
                    let box_at = |d: f32, grow: f32| {
                        let at = Isometry::new(
                            cast.pose.translation + direction * d,
                            cast.pose.rotation,
                        );
                        let s = Shape::cuboid(cast.half_extents + Vec3::splat(grow));
                        contact(&s, &at, shape, &target).is_some()
                    };
                    assert!(box_at(h.distance, 1e-4), "not touching: {context}");
                    if h.distance > 1e-3 {
                        assert!(
                            !box_at(h.distance - 1e-4, 0.0),
                            "already touching: {context}"
                        );
                    }
                    assert!(h.normal.is_normalized(), "{context}");
                    hits += 1;
                }
                (None, None) => misses += 1,
                // A graze: the two engines' tolerances decide differently; the box then passes
                // within a hair of the target.
                (ours, theirs) => {
                    let d = ours
                        .map(|h| h.distance)
                        .or(theirs.map(|t| t.time_of_impact));
                    let at = Isometry::new(
                        cast.pose.translation + direction * d.unwrap(),
                        cast.pose.rotation,
                    );
                    let grown = Shape::cuboid(cast.half_extents + Vec3::splat(1e-3));
                    assert!(contact(&grown, &at, shape, &target).is_some(), "{context}");
                }
            }
        }
        eprintln!("box cast at {shape:?}: {hits} hits, {misses} misses, worst {worst}");
        assert!(
            hits > 200 && misses > 10,
            "{shape:?}: {hits} hits, {misses} misses"
        );
    }
}

/// parry3d's capsule casts run up to 5e-3 from the contact (its rounded-segment GJK tolerance),
/// so each of ours is also checked independently: touching within 1e-4, apart 1e-4 before.
#[test]
fn capsule_casts_touch_within_1e_4_and_agree_with_parry3d_within_1e_2_of_gap_on_2500_casts() {
    use urto::geometry::Capsule;
    use urto::spatial::{CapsuleCast, cast_capsule};
    let mut rng = Rng::new(25);
    let mut scratch = QueryScratch::new();
    for (shape, parry_shape, _) in &shapes_with_parry_twins() {
        let (mut hits, mut misses, mut worst) = (0, 0, 0.0f32);
        for _ in 0..500 {
            let (target, aimed) = random_target_and_cast(&mut rng);
            let Some((start, direction)) = aimed else {
                continue;
            };
            let capsule = Capsule {
                half_length: rng.range(0.0, 0.7),
                radius: rng.range(0.1, 0.5),
            };
            let cast = CapsuleCast {
                pose: Isometry::new(start, rng.rotation()),
                capsule,
                direction,
                max_distance: 12.0,
            };
            let ours = cast_capsule(&cast, shape, &target, &mut scratch);
            let caster = parry3d::shape::Capsule::new_z(capsule.half_length, capsule.radius);
            let theirs = parry_cast(
                (&caster, &cast.pose),
                direction,
                (parry_shape.as_ref(), &target),
            );
            let context = format!("{shape:?} {cast:?} {target:?}: {ours:?} vs {theirs:?}");
            let capsule_at = |d: f32, grow: f32| {
                let at = Isometry::new(cast.pose.translation + direction * d, cast.pose.rotation);
                let s = Shape::capsule(capsule.half_length, capsule.radius + grow);
                contact(&s, &at, shape, &target).is_some()
            };
            match (ours, theirs) {
                (Some(h), Some(t)) => {
                    assert!(h.normal.is_normalized(), "{context}");
                    // Independently of parry: touching at our distance, apart 1e-4 before it.
                    assert!(capsule_at(h.distance, 1e-4), "not touching: {context}");
                    if h.distance > 1e-3 {
                        assert!(!capsule_at(h.distance - 1e-4, 0.0), "already: {context}");
                    }
                    let closing = h.normal.dot(direction).abs();
                    let error = (h.distance - t.time_of_impact).abs() * closing;
                    assert!(error < 1e-2, "{context}");
                    worst = worst.max(error);
                    hits += 1;
                }
                (None, None) => misses += 1,
                // A graze: the capsule passes within a hair of the target.
                (ours, theirs) => {
                    let d = ours
                        .map(|h| h.distance)
                        .or(theirs.map(|t| t.time_of_impact));
                    assert!(capsule_at(d.unwrap(), 1e-3), "{context}");
                }
            }
        }
        eprintln!("capsule cast at {shape:?}: {hits} hits, {misses} misses, worst {worst}");
        assert!(
            hits > 200 && misses > 5,
            "{shape:?}: {hits} hits, {misses} misses"
        );
    }
}

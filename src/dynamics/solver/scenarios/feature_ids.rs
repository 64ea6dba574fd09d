//! Warm starts that follow a contact's features (`warm_start.rs`): a body sliding or spinning
//! on a support moves its points across the support's frame, where they were matched by place
//! until the shape tests named their features. The same scene then ran two ways by which body
//! was spawned first (A's frame is the one the places are kept in). And on a tessellated
//! floor, points that stay the same points (`manifold_reduction.rs`).

use super::*;
use crate::geometry::{MeshCollider, TriMesh, box_hull};

/// The supports tried: the ground, a static box slab, a static hull slab, a tessellated floor.
/// (The floor joined at the thirty-seventh stop: a box sliding across it at 10 m/s sank
/// 0.14–0.16 mm until the thirty-fifth, and ended 0.45 mm apart by spawn order until the
/// thirty-seventh, when a box's points on a triangle came to keep their own depths; now the
/// same bits either way.)
fn supports() -> [(&'static str, Shape, Vec3); 4] {
    let slab = Vec3::new(20.0, 20.0, 0.5);
    let under = Vec3::new(0.0, 0.0, -0.5);
    [
        ("ground", Shape::half_space(Vec3::Z), Vec3::ZERO),
        ("box slab", Shape::cuboid(slab), under),
        ("hull slab", box_hull(slab), under),
        (
            "tessellated floor",
            Shape::TriMesh(MeshCollider::new(TriMesh::grid_floor(40.0, 40).unwrap()).unwrap()),
            Vec3::ZERO,
        ),
    ]
}

/// `body` (1 kg) set on `support` and launched with `motion` (velocity and spin, see
/// `Scene::launch`), the support spawned first or second: where it ends, how it moves, and how
/// far it sank below its resting height meanwhile.
fn launched(
    support: (&Shape, Vec3),
    body: &Shape,
    height: f32,
    motion: (Vec3, Vec3),
    support_first: bool,
) -> (Vec3, Vec3, Vec3, f32) {
    launched_renamed(support, body, height, motion, support_first, None)
}

/// [`launched`] with every contact point's feature id replaced by `renamed`, when set.
fn launched_renamed(
    (support, at): (&Shape, Vec3),
    body: &Shape,
    height: f32,
    motion: (Vec3, Vec3),
    support_first: bool,
    renamed: Option<crate::geometry::FeatureId>,
) -> (Vec3, Vec3, Vec3, f32) {
    let mut scene = Scene {
        renamed,
        ..Default::default()
    };
    let place = Vec3::new(0.0, 0.0, height);
    let (s, b) = if support_first {
        let s = scene.add(support.clone(), at, Quat::IDENTITY, 0.0);
        (s, scene.add(body.clone(), place, Quat::IDENTITY, 1.0))
    } else {
        let b = scene.add(body.clone(), place, Quat::IDENTITY, 1.0);
        (scene.add(support.clone(), at, Quat::IDENTITY, 0.0), b)
    };
    for k in [s, b] {
        scene.bodies[k].friction = 0.2;
    }
    let launch = scene.launch(b, motion);
    let (center, v, w) = launch.end;
    (center, v, w, launch.sank)
}

#[test]
fn a_box_sliding_at_10_m_s_and_a_plate_spun_at_10_rad_s_end_within_10_um_whichever_is_spawned_first_and_sink_under_10_um()
 {
    // Matched by place alone, a body whose support was A lost its warm start every step: it
    // sank 14 µm (sliding on the ground), 131 µm (spinning on the ground), 52 and 158 µm on a
    // box slab, 52 and 158 µm on a hull slab, against under 1 µm with the support as B. The
    // box slab keeps an asymmetry of its own (the speculative test grows whichever box is A),
    // 4 µm and 2 µm apart; the cube on the hull slab sinks 8 µm in both orders.
    let cube = (Shape::cuboid(Vec3::splat(0.5)), 0.5);
    let plate = (Shape::cuboid(Vec3::new(1.0, 1.0, 0.1)), 0.1);
    let sliding = (Vec3::new(10.0, 0.0, 0.0), Vec3::ZERO);
    let spinning = (Vec3::ZERO, Vec3::new(0.0, 0.0, 10.0));
    for (name, support, at) in supports() {
        for ((body, height), motion) in [(&cube, sliding), (&plate, spinning)] {
            let runs =
                [true, false].map(|first| launched((&support, at), body, *height, motion, first));
            let [(c0, v0, w0, sank0), (c1, v1, w1, sank1)] = runs;
            eprintln!("{name}: {c0} {v0} {w0} sank {sank0}; {c1} {v1} {w1} sank {sank1}");
            assert!(
                c0.distance(c1) < 1e-5 && v0.distance(v1) < 1e-4 && w0.distance(w1) < 1e-4,
                "{name}: support first {c0} {v0} {w0}, second {c1} {v1} {w1}"
            );
            for (sank, first) in [(sank0, true), (sank1, false)] {
                assert!(sank < 1e-5, "{name}, support first {first}: sank {sank} m");
            }
        }
    }
}

#[test]
fn on_a_tessellated_floor_a_box_sliding_at_10_m_s_and_a_plate_spun_at_10_rad_s_sink_under_5_um_and_the_plate_stays_within_1_mm()
 {
    // Until the reduction took a corner for its first point among points equally deep, a box
    // on the floor kept a point where a seam crossed its side instead of the corner beside it,
    // other points each step as it moved: the cube sank 137–156 µm, the plate 218–248 µm and
    // walked 1–2 cm (either spawn order).
    let floor = MeshCollider::new(TriMesh::grid_floor(40.0, 40).unwrap()).unwrap();
    let floor = (&Shape::TriMesh(floor), Vec3::ZERO);
    let cube = Shape::cuboid(Vec3::splat(0.5));
    let plate = Shape::cuboid(Vec3::new(1.0, 1.0, 0.1));
    for first in [true, false] {
        let sliding = (Vec3::new(10.0, 0.0, 0.0), Vec3::ZERO);
        let (_, _, _, sank) = launched(floor, &cube, 0.5, sliding, first);
        assert!(sank < 5e-6, "cube, floor first {first}: sank {sank} m");
        let spinning = (Vec3::ZERO, Vec3::new(0.0, 0.0, 10.0));
        let (at, _, _, sank) = launched(floor, &plate, 0.1, spinning, first);
        assert!(sank < 5e-6, "plate, floor first {first}: sank {sank} m");
        let walked = at.truncate().length();
        assert!(
            walked < 1e-3,
            "plate, floor first {first}: walked {walked} m"
        );
    }
}

#[test]
fn feature_ids_all_alike_or_all_unnamed_keep_a_sliding_box_and_a_spun_plate_finite_and_sinking_under_5_um_or_0_2_mm_with_the_support_as_a()
 {
    // Bad input: a game (or a contact hook) may hand the solver any ids. Of four points named
    // alike one is seeded by name (an old point seeds once), the rest by place; unnamed, all
    // by place.
    use crate::geometry::FeatureId;
    let support = (&Shape::half_space(Vec3::Z), Vec3::ZERO);
    let cube = Shape::cuboid(Vec3::splat(0.5));
    let plate = Shape::cuboid(Vec3::new(1.0, 1.0, 0.1));
    let sliding = (Vec3::new(10.0, 0.0, 0.0), Vec3::ZERO);
    let spinning = (Vec3::ZERO, Vec3::new(0.0, 0.0, 10.0));
    for renamed in [FeatureId(7), FeatureId(u32::MAX), FeatureId::NONE] {
        for ((body, height), motion) in [((&cube, 0.5), sliding), ((&plate, 0.1), spinning)] {
            for first in [true, false] {
                let (at, v, w, sank) =
                    launched_renamed(support, body, height, motion, first, Some(renamed));
                let finite = at.is_finite() && v.is_finite() && w.is_finite();
                assert!(finite, "{renamed:?}: {at} {v} {w}");
                // Matched by place alone, a support spawned first (A) costs the warm start: the
                // plate sank 131 µm so. With the body as A, its places match; a point named
                // alike may take another corner's impulses first (2.7 µm).
                let bound = if first { 2e-4 } else { 5e-6 };
                assert!(
                    sank < bound,
                    "{renamed:?}, support first {first}: sank {sank} m"
                );
            }
        }
    }
}

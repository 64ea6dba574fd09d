//! Bodies at rest stay put bit for bit: once a resting body has settled, the solver's answer to
//! its contact is the same every step, on a half-space and on a ground box of any thickness or
//! width. Until 2026-12-06 a ball on a 1 m slab alternated between two heights one ulp apart
//! every step, for ever, because the separation went through numbers as large as the distance
//! from the slab's centre (`contact.rs`, `on_moving`; `sphere_cuboid.rs`), and every such
//! body was indexed again by the broad phase each step.

use super::*;

/// Settles a scene for two seconds, then steps it `steps` times more: the poses of `bodies`
/// after each of those steps, as bits.
fn poses_after_settling(scene: &mut Scene, bodies: &[usize], steps: usize) -> Vec<Vec<[u32; 7]>> {
    scene.run(2.0);
    (0..steps)
        .map(|_| {
            scene.step();
            bodies
                .iter()
                .map(|&b| {
                    let (c, q) = (scene.bodies[b].center, scene.bodies[b].orientation);
                    let mut bits = [0; 7];
                    for (k, x) in c.to_array().into_iter().chain(q.to_array()).enumerate() {
                        bits[k] = x.to_bits();
                    }
                    bits
                })
                .collect()
        })
        .collect()
}

/// A static ground box of half extents `half`, its top face at z = 0, centred at `x` along x.
fn ground_box(scene: &mut Scene, half: Vec3, x: f32) -> usize {
    let centre = Vec3::new(x, 0.0, -half.z);
    scene.add(Shape::cuboid(half), centre, Quat::IDENTITY, 0.0)
}

/// Asserts that every pose after the first of `poses` is the first's.
fn assert_still(poses: &[Vec<[u32; 7]>], what: &str) {
    let moved = poses.iter().filter(|p| *p != &poses[0]).count();
    assert_eq!(moved, 0, "{what}: {moved} of {} steps moved", poses.len());
}

#[test]
fn balls_on_a_thin_a_20_m_thick_and_a_wide_slab_keep_their_position_bit_for_bit_for_60_steps() {
    // (half extents, the ground's centre along x): a 1 m slab, a 40 m thick one, and a 200 m
    // wide one whose centre is 60 m from the balls.
    let grounds = [
        (Vec3::new(5.0, 5.0, 0.5), 0.0),
        (Vec3::new(5.0, 5.0, 20.0), 0.3),
        (Vec3::new(100.0, 5.0, 0.5), 60.0),
    ];
    for (half, x) in grounds {
        let mut scene = Scene::default();
        ground_box(&mut scene, half, x);
        let balls: Vec<usize> = [(0.0, 0.5), (1.5, 0.25), (-2.0, 1.0)]
            .map(|(bx, r)| {
                let at = Vec3::new(bx, 0.3, r);
                scene.add(Shape::sphere(r), at, Quat::IDENTITY, 1.0)
            })
            .into();
        let poses = poses_after_settling(&mut scene, &balls, 60);
        assert_still(&poses, &format!("balls on a ground of half extents {half}"));
    }
}

//! The triangle–box depth (the mesh–box contacts' per-triangle test) against parry3d's
//! `contact`, an independent GJK/EPA: never shallower than the minimum translation distance,
//! deeper by at most the face bias.

use crate::common::rng::Rng;
use glam::Vec3;
use urto::geometry::contacts::contact_triangle_cuboid;
use urto::geometry::{Cuboid, Isometry};

/// Pairs within this of touching are not classified (parry's and our rounding differ there).
const BAND: f32 = 1e-4;

/// The triangle–box depth is the minimum translation distance: parry3d's GJK/EPA agrees.
#[test]
fn triangle_box_depth_agrees_with_parry() {
    use parry3d::math::{Pose, Rot3, Vector};
    let v = |x: Vec3| Vector::from_array(x.to_array());
    let mut rng = Rng::new(15);
    let (mut compared, mut worst) = (0, 0.0f32);
    for _ in 0..3000 {
        let tri =
            urto::geometry::Triangle::new(rng.in_ball(1.2), rng.in_ball(1.2), rng.in_ball(1.2));
        let cuboid = Cuboid {
            half_extents: rng.vec3(0.1, 0.8),
        };
        let at = Isometry::new(rng.in_ball(1.0), rng.rotation());
        let ours = contact_triangle_cuboid(&tri, &at, &cuboid);
        let pt = parry3d::shape::Triangle::new(v(tri.a), v(tri.b), v(tri.c));
        let pc = parry3d::shape::Cuboid::new(v(cuboid.half_extents));
        let pose = Pose::from_parts(v(at.translation), Rot3::from_array(at.rotation.to_array()));
        let theirs =
            parry3d::query::contact(&Pose::IDENTITY, &pt, &pose, &pc, 0.0).expect("supported");
        match (ours, theirs) {
            (Some(m), Some(c)) if c.dist < -BAND => {
                // Never shallower than the minimum translation distance; deeper by at most the
                // face bias (an edge axis must beat a face axis by 5%, see triangle_cuboid.rs).
                compared += 1;
                let (ours, mtd) = (m.max_depth(), -c.dist);
                let slack = 1e-4 + 1e-3 * cuboid.half_extents.max_element();
                assert!(ours >= mtd - 1e-4, "ours {ours} shallower than parry {mtd}");
                assert!(ours <= mtd / 0.95 + slack, "ours {ours} parry {mtd}");
                worst = worst.max(ours / mtd);
            }
            (Some(m), None) => assert!(
                m.max_depth() < BAND,
                "parry sees no contact, ours {}",
                m.max_depth()
            ),
            (None, Some(c)) => assert!(c.dist > -BAND, "we see none, parry {}", c.dist),
            _ => {}
        }
    }
    assert!(compared > 500, "{compared}");
    println!("triangle-box depth vs parry: {compared} compared, worst ratio {worst}");
}

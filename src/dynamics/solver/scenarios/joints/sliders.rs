//! Sliders: a block stopped by its limit on a sloping rail, and a block sliding metres along a
//! rail fixed in the world, named as the joint's first end or its second (the rail rides on
//! the heavier end, `slider_rail` in `joint_extra.rs`).

use super::*;

#[test]
fn a_slider_on_a_30_degree_rail_stops_at_its_limit_and_stays_on_the_rail_within_1_mm() {
    let mut scene = Scene::default();
    let base = anchor(&mut scene, Vec3::ZERO);
    let rail = Vec3::new(30f32.to_radians().cos(), 0.0, -30f32.to_radians().sin());
    let block = scene.add(
        Shape::cuboid(Vec3::splat(0.1)),
        Vec3::ZERO,
        Quat::IDENTITY,
        2.0,
    );
    let slider = JointKind::Prismatic {
        limit: Some(JointLimit {
            min: -1.0,
            max: 2.0,
        }),
        motor: None,
    };
    join(
        &mut scene,
        (base, block),
        (Vec3::ZERO, Vec3::ZERO),
        rail,
        slider,
    );
    scene.run(3.0);
    let c = scene.bodies[block].center;
    let along = c.dot(rail);
    let across = (c - rail * along).length();
    assert!((along - 2.0).abs() < 0.01, "stopped at {along} m");
    assert!(across < 1e-3, "{across} m off the rail");
    let turned = scene.bodies[block]
        .orientation
        .angle_between(Quat::IDENTITY);
    assert!(turned < 1e-3, "turned {turned} rad");
}

/// A 2 kg block at the origin sliding at 2 m/s along x under gravity, on a slider along x to a
/// fixed point at the origin, the block named first when `block_first`; travel limited to
/// `limit`. Where the block is after `seconds`, and how far it turned.
fn slide_along_a_fixed_rail(
    block_first: bool,
    limit: Option<JointLimit>,
    seconds: f32,
) -> (Vec3, f32) {
    let mut scene = Scene::default();
    let base = anchor(&mut scene, Vec3::ZERO);
    let block = scene.add(
        Shape::cuboid(Vec3::splat(0.1)),
        Vec3::ZERO,
        Quat::IDENTITY,
        2.0,
    );
    scene.bodies[block].v = Vec3::new(2.0, 0.0, 0.0);
    let ends = if block_first {
        (block, base)
    } else {
        (base, block)
    };
    let kind = JointKind::Prismatic { limit, motor: None };
    join(&mut scene, ends, (Vec3::ZERO, Vec3::ZERO), Vec3::X, kind);
    scene.run(seconds);
    let b = &scene.bodies[block];
    (b.center, b.orientation.angle_between(Quat::IDENTITY))
}

/// Asserts that a block the slider carried ended at `x` along the rail within `within`, on the
/// rail within 1 mm and turned by under 1 mrad (`(at, turned)` as the slide left it).
fn on_the_rail_at(case: &str, (at, turned): (Vec3, f32), x: f32, within: f32) {
    assert!((at.x - x).abs() < within, "{case}: at {at}");
    let off = Vec3::new(0.0, at.y, at.z).length();
    assert!(off < 1e-3, "{case}: {off} m off the rail");
    assert!(turned < 1e-3, "{case}: turned {turned} rad");
}

#[test]
fn a_block_sliding_6_m_along_a_fixed_rail_stays_on_it_within_1_mm_whichever_end_it_is() {
    for block_first in [false, true] {
        let end = slide_along_a_fixed_rail(block_first, None, 3.0);
        // Nothing along the rail resists: 2 m/s for 3 s.
        on_the_rail_at(&format!("block first {block_first}"), end, 6.0, 0.01);
    }
}

#[test]
fn a_slider_limit_stops_the_block_at_the_same_place_within_1_cm_whichever_end_it_is() {
    // The travel is B's anchor from A's along the axis: +x of the block when the base is A,
    // −x when the block is A. A bound of 1 m on the travel ahead stops it 1 m out either way.
    for (block_first, (min, max)) in [(false, (-5.0, 1.0)), (true, (-1.0, 5.0))] {
        let end = slide_along_a_fixed_rail(block_first, Some(JointLimit { min, max }), 2.0);
        on_the_rail_at(&format!("block first {block_first}"), end, 1.0, 0.01);
    }
}

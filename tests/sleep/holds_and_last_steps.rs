//! What holds a body up going, or changing, while it sleeps or on the very step it would fall
//! asleep: a rope to the world cut, disabled or its static hook gone (`wake_on_joints.rs`), a
//! floor removed or a gravity scale turned round on the falling-asleep step (an island pulled
//! by gravity and held by nothing never sleeps, `dynamics/islands.rs`; a body's written
//! make-up counts its stillness from zero, `plugins/sleep.rs`). Each was found by a
//! user-style probe: the body hung in the air, asleep, for good.

use super::*;

/// A game's edit of a scene: the world, then two of its entities.
type Edit = fn(&mut World, Entity, Entity);

/// Whether a box's height 1 s after an edit is what the edit makes it.
type Expected = fn(f32) -> bool;

/// A 1 kg ball hanging asleep 1 m under a ball joint to `hook` (the world when `None`).
fn ball_asleep_on_a_rope(app: &mut App, hook: Option<Entity>) -> (Entity, Entity) {
    let ball = app
        .world_mut()
        .spawn((
            Collider::sphere(0.1),
            Mass(1.0),
            Position::new(0.0, 0.0, 4.0),
            Velocity::default(),
        ))
        .id();
    let joint = match hook {
        Some(hook) => Joint::spherical(ball, hook).with_anchors(Vec3::Z, Vec3::ZERO),
        None => {
            Joint::spherical(ball, JointEnd::World).with_anchors(Vec3::Z, Vec3::new(0.0, 0.0, 5.0))
        }
    };
    let joint = app.world_mut().spawn(joint).id();
    urto::step(app.world_mut(), 120).unwrap();
    assert!(asleep(app, ball), "the ball sleeps on its rope");
    (ball, joint)
}

#[test]
fn a_ball_asleep_on_a_rope_cut_disabled_or_unhooked_falls_over_4_m_within_1_s() {
    let cuts: [(&str, Edit); 5] = [
        ("joint despawned", |w, joint, _| {
            w.despawn(joint);
        }),
        ("Joint removed", |w, joint, _| {
            w.entity_mut(joint).remove::<Joint>();
        }),
        ("joint disabled", |w, joint, _| {
            w.entity_mut(joint).insert(JointDisabled);
        }),
        ("hook despawned", |w, _, hook| {
            w.despawn(hook);
        }),
        ("hook's collider removed, then the hook", |w, _, hook| {
            w.entity_mut(hook).remove::<Collider>();
            w.despawn(hook);
        }),
    ];
    for (cut, apply) in cuts {
        let mut app = common::app();
        app.insert_resource(Gravity::EARTH_Z_UP);
        let hook = app
            .world_mut()
            .spawn((
                Collider::cuboid(0.1, 0.1, 0.1),
                Position::new(0.0, 0.0, 5.0),
                Static,
            ))
            .id();
        let (ball, joint) = ball_asleep_on_a_rope(&mut app, Some(hook));
        apply(app.world_mut(), joint, hook);
        urto::step(app.world_mut(), 60).unwrap();
        // Free fall from z = 4: 4.9 m in 1 s. Before: z = 4, asleep.
        assert!(z(&app, ball) < 0.0, "{cut}: z = {}", z(&app, ball));
    }
    // Re-anchored 1 m higher, a ball on a rope to the world rises to it.
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let (ball, joint) = ball_asleep_on_a_rope(&mut app, None);
    app.world_mut().get_mut::<Joint>(joint).unwrap().anchor_b.z += 1.0;
    urto::step(app.world_mut(), 60).unwrap();
    assert!((z(&app, ball) - 5.0).abs() < 0.01, "z = {}", z(&app, ball));
}

#[test]
fn a_write_on_the_step_a_box_would_fall_asleep_acts_within_1_s_as_a_step_earlier() {
    let (mut app, _, b) = box_on_a_slab(0.5);
    let mut last_awake = 0;
    while !asleep(&app, b) {
        assert!(last_awake < 300, "the box never sleeps");
        last_awake += 1;
        urto::step(app.world_mut(), 1).unwrap();
    }
    last_awake -= 1;
    let edits: [(&str, Edit, Expected); 6] = [
        (
            "slab despawned",
            |w, slab, _| {
                w.despawn(slab);
            },
            |z| z < -3.0,
        ),
        (
            "slab's collider removed",
            |w, slab, _| {
                w.entity_mut(slab).remove::<Collider>();
            },
            |z| z < -3.0,
        ),
        (
            "slab moved down 1 m",
            |w, slab, _| {
                w.get_mut::<Position>(slab).unwrap().0.z -= 1.0;
            },
            |z| z < -0.4,
        ),
        (
            "gravity scale -1",
            |w, _, b| {
                w.entity_mut(b).insert(GravityScale(-1.0));
            },
            |z| z > 3.0,
        ),
        (
            "box made a sensor",
            |w, _, b| {
                w.entity_mut(b).insert(Sensor);
            },
            |z| z < -3.0,
        ),
        (
            "box colliding with nothing",
            |w, _, b| {
                let none = CollisionLayers::new(LayerMask(1), LayerMask(0));
                w.entity_mut(b).insert(none);
            },
            |z| z < -3.0,
        ),
    ];
    for (edit, apply, expected) in edits {
        for at in [last_awake - 1, last_awake] {
            let (mut app, slab, b) = box_on_a_slab(0.5);
            urto::step(app.world_mut(), at).unwrap();
            assert!(!asleep(&app, b));
            apply(app.world_mut(), slab, b);
            urto::step(app.world_mut(), 60).unwrap();
            // Before: after `last_awake` steps, z = 0.5 (0.502 turned round), asleep.
            assert!(
                expected(z(&app, b)),
                "{edit} after {at} steps: z = {}",
                z(&app, b)
            );
        }
    }
}

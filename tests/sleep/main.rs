//! Sleeping: still bodies stop being simulated, keep their contacts, and wake when something
//! touches, moves or pushes them.

#[path = "../common/mod.rs"]
mod common;
mod game_changes;
mod holds_and_last_steps;
mod support_changes;

use bevy_app::App;
use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use urto::prelude::*;

/// An app on the ground with the default settings, in which sleeping is on.
fn sleepy_app() -> App {
    common::on_ground(common::app())
}

/// A unit box on a static 10 × 10 × 1 m slab (top at z = 0), both with `friction`, at rest on
/// it; the app (gravity 9.8 along −z), the slab and the box.
fn box_on_a_slab(friction: f32) -> (App, Entity, Entity) {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let slab = app
        .world_mut()
        .spawn((
            Collider::cuboid(5.0, 5.0, 0.5),
            Position::new(0.0, 0.0, -0.5),
            Static,
            Friction(friction),
        ))
        .id();
    let b = common::crate_box(&mut app, 0.5);
    app.world_mut().entity_mut(b).insert(Friction(friction));
    (app, slab, b)
}

fn asleep(app: &App, e: Entity) -> bool {
    app.world().get::<Sleeping>(e).is_some()
}

fn z(app: &App, e: Entity) -> f32 {
    app.world().get::<Position>(e).unwrap().0.z
}

fn counter(app: &App, name: &str) -> f64 {
    app.world()
        .resource::<PhysicsStats>()
        .counter(name)
        .unwrap_or(0.0)
}

/// Balls dropped on the ground come to rest and fall asleep within 2 s; asleep, they are not
/// integrated, their ground contacts are not recomputed, and no collision is reported as ended.
#[test]
fn resting_balls_fall_asleep_and_cost_nothing() {
    let mut app = sleepy_app();
    let balls: Vec<Entity> = (0..10)
        .map(|i| common::ball(&mut app, Vec3::new(i as f32 * 2.0, 0.0, 0.6)))
        .collect();
    urto::step(app.world_mut(), 120).unwrap();
    assert!(balls.iter().all(|b| asleep(&app, *b)));
    let mut ended = app
        .world()
        .resource::<Messages<CollisionEnded>>()
        .get_cursor();
    let before: Vec<f32> = balls.iter().map(|b| z(&app, *b)).collect();
    urto::step(app.world_mut(), 60).unwrap();
    assert_eq!(counter(&app, "integrate/bodies"), 0.0);
    assert_eq!(counter(&app, "narrow_phase/contacts"), 0.0);
    let after: Vec<f32> = balls.iter().map(|b| z(&app, *b)).collect();
    assert_eq!(before, after, "sleeping bodies do not move");
    let ended = ended
        .read(app.world().resource::<Messages<CollisionEnded>>())
        .count();
    assert_eq!(ended, 0, "falling asleep ends no collision");
}

/// Sleeping is on by default; turned off, a resting ball never sleeps and is integrated every
/// step (the lecture's pipeline, whose integrate stage counts its bodies).
#[test]
fn sleeping_is_on_by_default_and_off_when_disabled() {
    assert!(SleepSettings::default().enabled);
    let mut app = common::legacy_app();
    app.insert_resource(Gravity::EARTH_Z_UP)
        .insert_resource(SleepSettings {
            enabled: false,
            ..Default::default()
        });
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    let b = common::ball(&mut app, Vec3::new(0.0, 0.0, 0.6));
    urto::step(app.world_mut(), 120).unwrap();
    assert!(!asleep(&app, b));
    assert_eq!(counter(&app, "integrate/bodies"), 1.0);
}

/// A stack of three boxes falls asleep as one island (one key for all three, in the same step),
/// and a push on the bottom box wakes the whole stack before the next step moves anything.
#[test]
fn a_stack_sleeps_and_wakes_as_one_island_within_one_step() {
    let mut app = sleepy_app();
    let stack: Vec<Entity> = (0..3)
        .map(|i| common::crate_box(&mut app, 0.5 + i as f32))
        .collect();
    let states = |app: &App| -> Vec<SleepState> {
        stack
            .iter()
            .map(|&e| *app.world().get::<SleepState>(e).unwrap())
            .collect()
    };
    let mut slept_at = None;
    for step in 0..180 {
        urto::step(app.world_mut(), 1).unwrap();
        let count = stack.iter().filter(|&&b| asleep(&app, b)).count();
        assert!(count == 0 || count == 3, "step {step}: {count} of 3 asleep");
        if count == 3 {
            slept_at = Some(step);
            break;
        }
    }
    assert!(slept_at.is_some(), "the stack never slept");
    let s = states(&app);
    assert!(s[0].island != 0 && s.iter().all(|x| x.island == s[0].island));
    app.world_mut().get_mut::<Velocity>(stack[0]).unwrap().0 = Vec3::new(0.5, 0.0, 0.0);
    urto::step(app.world_mut(), 1).unwrap();
    assert!(stack.iter().all(|&b| !asleep(&app, b)));
    assert!(states(&app).iter().all(|s| s.island == 0));
}

/// Despawning the bottom box of a sleeping stack of three wakes the two above it (the middle one
/// lost a contact; the top one is in its island), and they fall: the top box ends at least
/// 0.9 m lower within a second.
#[test]
fn despawning_the_bottom_of_a_sleeping_stack_wakes_the_whole_island() {
    let mut app = sleepy_app();
    let stack: Vec<Entity> = (0..3)
        .map(|i| common::crate_box(&mut app, 0.5 + i as f32))
        .collect();
    urto::step(app.world_mut(), 180).unwrap();
    assert!(stack.iter().all(|&b| asleep(&app, b)), "the stack slept");
    let top_before = z(&app, stack[2]);
    app.world_mut().despawn(stack[0]);
    urto::step(app.world_mut(), 1).unwrap();
    assert!(!asleep(&app, stack[1]) && !asleep(&app, stack[2]));
    urto::step(app.world_mut(), 60).unwrap();
    assert!(
        z(&app, stack[2]) < top_before - 0.9,
        "{}",
        z(&app, stack[2])
    );
}

/// A ball dropped on a sleeping ball wakes it: the two then move as two awake bodies would.
#[test]
fn a_falling_ball_wakes_the_one_it_hits() {
    let mut app = sleepy_app();
    let lower = common::ball(&mut app, Vec3::new(0.0, 0.0, 0.5));
    urto::step(app.world_mut(), 60).unwrap();
    assert!(asleep(&app, lower));
    // Slightly off-centre, so the lower ball is pushed sideways.
    common::ball(&mut app, Vec3::new(0.3, 0.0, 3.0));
    let mut woke = false;
    for _ in 0..60 {
        urto::step(app.world_mut(), 1).unwrap();
        woke |= !asleep(&app, lower);
    }
    assert!(woke, "the hit woke the lower ball");
    let x = app.world().get::<Position>(lower).unwrap().0.x;
    assert!(x < -0.01, "pushed aside: x = {x}");
}

/// Game code wakes a sleeping body by setting its velocity, moving it, or pushing it.
#[test]
fn game_code_wakes_a_sleeping_body() {
    for poke in 0..3 {
        let mut app = sleepy_app();
        let b = common::ball(&mut app, Vec3::new(0.0, 0.0, 0.5));
        urto::step(app.world_mut(), 60).unwrap();
        assert!(asleep(&app, b));
        let mut e = app.world_mut().entity_mut(b);
        match poke {
            0 => e.get_mut::<Velocity>().unwrap().0 = Vec3::new(0.0, 0.0, 5.0),
            1 => e.get_mut::<Position>().unwrap().0.z = 3.0,
            _ => {
                e.insert(Force(Vec3::new(0.0, 0.0, 2000.0)));
            }
        }
        urto::step(app.world_mut(), 1).unwrap();
        assert!(!asleep(&app, b), "poke {poke}");
        assert!(
            z(&app, b) > 0.52,
            "poke {poke}: it moved up, z = {}",
            z(&app, b)
        );
    }
}

/// A box asleep on a sleeping box wakes and falls when the lower one is despawned.
#[test]
fn removing_the_support_wakes_what_rested_on_it() {
    let mut app = sleepy_app();
    let lower = app
        .world_mut()
        .spawn((
            Collider::cuboid(0.5, 0.5, 0.5),
            Position::new(0.0, 0.0, 0.5),
            Velocity::default(),
        ))
        .id();
    let upper = app
        .world_mut()
        .spawn((
            Collider::cuboid(0.5, 0.5, 0.5),
            Position::new(0.0, 0.0, 1.5),
            Velocity::default(),
        ))
        .id();
    urto::step(app.world_mut(), 120).unwrap();
    assert!(asleep(&app, lower) && asleep(&app, upper));
    app.world_mut().despawn(lower);
    urto::step(app.world_mut(), 60).unwrap();
    assert!(
        z(&app, upper) < 0.6,
        "fell to the ground: z = {}",
        z(&app, upper)
    );
}

/// Once a pile sleeps, no stage looks at it: the broad phase pairs none of its bodies (with
/// scenery or with each other), the narrow phase tests nothing, the solver gets no body and
/// the sleep check no candidate; and no position changes by a single bit.
#[test]
fn a_sleeping_pile_gets_zero_pairs_zero_solver_bodies_and_zero_sleep_candidates() {
    let mut app = sleepy_app();
    let mut bodies: Vec<Entity> = (0..12)
        .map(|i| {
            common::ball(
                &mut app,
                Vec3::new((i % 4) as f32 * 1.001, (i / 4) as f32 * 1.001, 0.5),
            )
        })
        .collect();
    bodies.extend((0..3).map(|i| common::crate_box(&mut app, 0.5 + i as f32)));
    for b in &mut bodies[12..] {
        app.world_mut().get_mut::<Position>(*b).unwrap().0.x = 10.0;
    }
    urto::step(app.world_mut(), 240).unwrap();
    assert!(bodies.iter().all(|&b| asleep(&app, b)), "the pile slept");
    let before: Vec<Vec3> = bodies.iter().map(|&b| position(&app, b)).collect();
    urto::step(app.world_mut(), 30).unwrap();
    for name in [
        "broad_phase/pairs",
        "broad_phase/static_pairs",
        "narrow_phase/contacts",
        "soft_step/bodies",
        "sleep/awake_bodies",
    ] {
        assert_eq!(counter(&app, name), 0.0, "{name}");
    }
    assert!(counter(&app, "sleep/sleeping_islands") >= 1.0);
    // Untested, the pile's contacts still count as touching: 12 balls and 3 boxes on the ground
    // or on each other.
    assert!(counter(&app, "collisions/touching_pairs") >= 15.0);
    let after: Vec<Vec3> = bodies.iter().map(|&b| position(&app, b)).collect();
    assert_eq!(before, after);
}

/// Three boxes stacked on the ground, stepped until they sleep (checked).
fn sleeping_stack() -> (App, Vec<Entity>) {
    let mut app = sleepy_app();
    let stack: Vec<Entity> = (0..3)
        .map(|i| common::crate_box(&mut app, 0.5 + i as f32))
        .collect();
    urto::step(app.world_mut(), 240).unwrap();
    assert!(stack.iter().all(|&b| asleep(&app, b)));
    (app, stack)
}

fn position(app: &App, e: Entity) -> Vec3 {
    app.world().get::<Position>(e).unwrap().0
}

/// Validation leaves sleeping bodies out, so a bad value written to a sleeper must wake it: a
/// NaN mass is quarantined within one step, and its sleeping neighbours stay finite.
#[test]
fn a_nan_mass_written_to_a_sleeping_body_is_quarantined_within_one_step() {
    let (mut app, stack) = sleeping_stack();
    app.world_mut().entity_mut(stack[1]).insert(Mass(f32::NAN));
    urto::step(app.world_mut(), 1).unwrap();
    assert!(app.world().get::<Quarantined>(stack[1]).is_some());
    urto::step(app.world_mut(), 60).unwrap();
    for b in [stack[0], stack[2]] {
        assert!(position(&app, b).is_finite());
    }
}

/// Game code may wake a body by removing its marker: the whole island wakes before the next
/// step simulates anything.
#[test]
fn removing_the_sleeping_marker_wakes_the_whole_island_within_one_step() {
    let (mut app, stack) = sleeping_stack();
    app.world_mut().entity_mut(stack[2]).remove::<Sleeping>();
    urto::step(app.world_mut(), 1).unwrap();
    assert!(stack.iter().all(|&b| !asleep(&app, b)));
    assert_eq!(counter(&app, "soft_step/awake_bodies"), 3.0);
}

/// Balls asleep on a ground wake when the ground is despawned (their dormant contacts end,
/// reported as ended collisions), and fall at least 1 m within a second.
#[test]
fn despawning_the_ground_wakes_the_balls_asleep_on_it_and_they_fall_1m_within_1s() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let ground = app
        .world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static))
        .id();
    let balls: Vec<Entity> = (0..4)
        .map(|i| common::ball(&mut app, Vec3::new(i as f32 * 2.0, 0.0, 0.5)))
        .collect();
    urto::step(app.world_mut(), 120).unwrap();
    assert!(balls.iter().all(|&b| asleep(&app, b)));
    let mut ended = app
        .world()
        .resource::<Messages<CollisionEnded>>()
        .get_cursor();
    app.world_mut().despawn(ground);
    let mut count = 0;
    for _ in 0..60 {
        urto::step(app.world_mut(), 1).unwrap();
        count += ended
            .read(app.world().resource::<Messages<CollisionEnded>>())
            .count();
    }
    assert_eq!(count, balls.len());
    for &b in &balls {
        assert!(z(&app, b) < -0.5, "fell: z = {}", z(&app, b));
    }
}

/// A game component the physics knows nothing about.
#[derive(Component)]
struct Tag;

/// How a test writes to one sleeping body.
type Write = fn(&mut EntityWorldMut);

/// Every write game code can make to a sleeping body wakes that body and no other, whether the
/// component was there (a change through `Mut`) or is inserted, in any of the sleeping tables;
/// a write that leaves a value as it slept (`set_changed` on the pose) and a write to a
/// component the physics does not read wake nothing. Sleepers are found through the tables'
/// summary ticks, so this checks that no write goes unseen and that one write does not wake
/// its table.
#[test]
fn each_of_21_writes_wakes_only_the_body_written_among_60_sleepers_in_three_tables() {
    let mut app = sleepy_app();
    let balls: Vec<Entity> = (0..60)
        .map(|i| {
            let at = Vec3::new((i % 10) as f32 * 3.0, (i / 10) as f32 * 3.0, 0.5);
            let b = common::ball(&mut app, at);
            let mut e = app.world_mut().entity_mut(b);
            match i % 3 {
                0 => {}
                1 => {
                    e.insert(Tag);
                }
                _ => {
                    let layers = CollisionLayers::default();
                    e.insert((LinearDrag(0.1), Force(Vec3::ZERO), Mass(1.5), layers));
                }
            }
            b
        })
        .collect();
    urto::step(app.world_mut(), 120).unwrap();
    assert!(balls.iter().all(|&b| asleep(&app, b)), "all asleep");
    let unseen: [Write; 2] = [
        |e| e.get_mut::<Position>().unwrap().set_changed(),
        |e| {
            e.insert(Tag);
        },
    ];
    for (i, write) in unseen.iter().enumerate() {
        write(&mut app.world_mut().entity_mut(balls[3 * i]));
        urto::step(app.world_mut(), 1).unwrap();
        assert!(balls.iter().all(|&b| asleep(&app, b)), "unseen write {i}");
    }
    // (ball, write): balls 20 to 36, 50 and 53, rows of all three tables; a write to a component
    // the ball has changes it in place (`Force`, `LinearDrag`, `Mass` and `CollisionLayers` on
    // balls `i % 3 == 2`),
    // one it lacks is inserted (the ball moves to a table of its own).
    let writes: [(usize, Write); 21] = [
        (20, |e| e.get_mut::<Position>().unwrap().0.x += 0.1),
        (21, |e| {
            e.get_mut::<Rotation>().unwrap().0 = Quat::from_rotation_z(0.3)
        }),
        (22, |e| e.get_mut::<Velocity>().unwrap().0 = Vec3::Z),
        (23, |e| {
            e.insert(AngularVelocity::new(0.0, 0.0, 2.0));
        }),
        (26, |e| e.get_mut::<Force>().unwrap().0 = Vec3::X),
        (25, |e| {
            e.insert(Torque(Vec3::Z));
        }),
        (24, |e| {
            let mut push = ForceAtPoint::default();
            push.add(Vec3::X, Vec3::Z);
            e.insert(push);
        }),
        (27, |e| {
            e.insert(Impulse::new(Vec3::X));
        }),
        (28, |e| {
            e.insert(GravityScale(0.5));
        }),
        (29, |e| e.get_mut::<Mass>().unwrap().0 = 2.0),
        (30, |e| {
            e.insert(Density(3.0));
        }),
        (31, |e| {
            e.insert(LockedAxes::ROTATION_LOCKED);
        }),
        (32, |e| {
            e.insert(Collider::sphere(0.4));
        }),
        (33, |e| {
            e.insert(Inertia::custom(Vec3::ONE, Quat::IDENTITY));
        }),
        (35, |e| e.get_mut::<LinearDrag>().unwrap().0 = 0.3),
        (34, |e| {
            e.insert(AngularDrag(0.2));
        }),
        (50, |e| {
            e.remove::<Mass>();
        }),
        (36, |e| {
            e.insert(CollisionLayers::new(LayerMask::ALL, LayerMask::DEFAULT));
        }),
        (53, |e| {
            e.remove::<CollisionLayers>();
        }),
        (37, |e| {
            e.insert(Friction(0.1));
        }),
        (38, |e| {
            e.insert(Restitution(0.9));
        }),
    ];
    for (i, &(ball, write)) in writes.iter().enumerate() {
        let written = balls[ball];
        write(&mut app.world_mut().entity_mut(written));
        urto::step(app.world_mut(), 1).unwrap();
        assert!(!asleep(&app, written), "write {i} woke its body");
        let woken = balls.iter().filter(|&&b| !asleep(&app, b)).count();
        assert_eq!(woken, i + 1, "write {i} woke only its body");
    }
}

/// Static bodies settle after their first step (they leave the change scans); a game's later
/// writes to one still reach every stage within a step: a box moved under a falling ball
/// catches it, a box whose collider grew lifts the ball resting on it, and a box made dynamic
/// falls; a box moved through its `Transform` catches a ball too. Without the writes the balls
/// would rest on the ground (centre 0.5 m up) and the box
/// would hang at 3 m.
#[test]
fn a_settled_static_moved_reshaped_or_made_dynamic_acts_on_the_next_step_within_1cm() {
    let mut app = sleepy_app();
    let unit_box = || Collider::cuboid(0.5, 0.5, 0.5);
    let far_box = app
        .world_mut()
        .spawn((unit_box(), Position(Vec3::new(20.0, 0.0, 0.5)), Static))
        .id();
    let under_box = app
        .world_mut()
        .spawn((unit_box(), Position(Vec3::new(5.0, 0.0, 0.5)), Static))
        .id();
    let hanging_box = app
        .world_mut()
        .spawn((unit_box(), Position(Vec3::new(-5.0, 0.0, 3.0)), Static))
        .id();
    let drawn_box = app
        .world_mut()
        .spawn((
            unit_box(),
            Position(Vec3::new(40.0, 0.0, 0.5)),
            bevy_transform::components::Transform::from_xyz(40.0, 0.0, 0.5),
            Static,
        ))
        .id();
    let falling = common::ball(&mut app, Vec3::new(0.0, 0.0, 2.5));
    let falling_on_drawn = common::ball(&mut app, Vec3::new(-10.0, 0.0, 2.5));
    let resting = common::ball(&mut app, Vec3::new(5.0, 0.0, 1.5));
    urto::step(app.world_mut(), 5).unwrap();
    app.world_mut().get_mut::<Position>(far_box).unwrap().0 = Vec3::new(0.0, 0.0, 0.5);
    *app.world_mut().get_mut::<Collider>(under_box).unwrap() = Collider::cuboid(1.0, 1.0, 1.0);
    let mut drawn = app
        .world_mut()
        .get_mut::<bevy_transform::components::Transform>(drawn_box);
    drawn.as_mut().unwrap().translation = Vec3::new(-10.0, 0.0, 0.5);
    app.world_mut()
        .entity_mut(hanging_box)
        .remove::<Static>()
        .insert((Velocity::default(), Mass(1.0)));
    urto::step(app.world_mut(), 240).unwrap();
    let on_moved_box = z(&app, falling);
    assert!(
        (on_moved_box - 1.5).abs() < 0.01,
        "caught at z = {on_moved_box}"
    );
    let on_grown_box = z(&app, resting);
    assert!(
        (on_grown_box - 2.0).abs() < 0.01,
        "lifted to z = {on_grown_box}"
    );
    let on_drawn_box = z(&app, falling_on_drawn);
    assert!(
        (on_drawn_box - 1.5).abs() < 0.01,
        "caught by the Transform's box at z = {on_drawn_box}"
    );
    let fallen = z(&app, hanging_box);
    assert!((fallen - 0.5).abs() < 0.01, "fell to z = {fallen}");
}

/// Sleeping by displacement (`src/dynamics/stillness.rs`): a 20-row pyramid of 210 boxes, whose
/// stiff contacts keep it breathing by a few millimetres at 3 Hz (boxes passing 0.1 m/s), falls
/// asleep within 1 s of being built, every box within 1 cm of where it stood (by the speed rule
/// it slept after 2.6 s).
#[test]
fn a_breathing_210_box_pyramid_sleeps_within_1_s_every_box_within_1_cm() {
    let mut app = sleepy_app();
    let mut boxes = Vec::new();
    for row in 0..20 {
        let count = 20 - row;
        for k in 0..count {
            let y = (k as f32 - (count - 1) as f32 * 0.5) * 1.01;
            let at = Vec3::new(0.0, y, 0.5 + row as f32);
            let body = (
                Collider::cuboid(0.5, 0.5, 0.5),
                Position(at),
                Velocity::default(),
            );
            boxes.push((app.world_mut().spawn(body).id(), at));
        }
    }
    urto::step(app.world_mut(), 60).unwrap();
    for &(b, at) in &boxes {
        assert!(asleep(&app, b), "a box still awake after 1 s");
        let moved = position(&app, b).distance(at);
        assert!(moved < 0.01, "a box moved {moved} m");
    }
}

/// A turning point is not a resting place: a 1 m pendulum swinging by 10° (0.55 m/s at the
/// bottom) slows to a stop at each end, but any half-second window there holds more than the
/// 2.5 cm a still body may move, so it is never frozen and still swings by more than 8° after
/// 5 s (below about 5° it could freeze at an end: see the README's limits).
#[test]
fn a_pendulum_swinging_10_degrees_never_sleeps_in_5_s_and_keeps_8_degrees() {
    let mut app = sleepy_app();
    let pivot = Vec3::new(0.0, 0.0, 5.0);
    let start = 10f32.to_radians();
    let at = pivot + Vec3::new(start.sin(), 0.0, -start.cos());
    let bob = app
        .world_mut()
        .spawn((Collider::sphere(0.05), Position(at), Velocity::default()))
        .id();
    app.world_mut()
        .spawn(Joint::spherical(bob, JointEnd::World).with_anchors(pivot - at, pivot));
    let mut widest = 0.0f32;
    for step in 0..300 {
        urto::step(app.world_mut(), 1).unwrap();
        assert!(!asleep(&app, bob), "frozen at step {step}");
        if step >= 240 {
            let x = position(&app, bob).x;
            widest = widest.max(x.clamp(-1.0, 1.0).asin().abs()); // a 1 m rope
        }
    }
    assert!(
        widest > 8f32.to_radians(),
        "{} degrees",
        widest.to_degrees()
    );
}

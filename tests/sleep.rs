//! Sleeping: still bodies stop being simulated, keep their contacts, and wake when something
//! touches, moves or pushes them.

mod common;

use bevy_app::App;
use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;
use glam::Vec3;
use urto::prelude::*;

fn sleepy_app() -> App {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP)
        .insert_resource(SleepSettings {
            enabled: true,
            ..Default::default()
        });
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    app
}

fn ball(app: &mut App, at: Vec3) -> Entity {
    app.world_mut()
        .spawn((Collider::sphere(0.5), Position(at), Velocity::default()))
        .id()
}

fn asleep(app: &App, e: Entity) -> bool {
    app.world().get::<SleepState>(e).unwrap().asleep
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
        .map(|i| ball(&mut app, Vec3::new(i as f32 * 2.0, 0.0, 0.6)))
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
    let b = ball(&mut app, Vec3::new(0.0, 0.0, 0.6));
    urto::step(app.world_mut(), 120).unwrap();
    assert!(!asleep(&app, b));
    assert_eq!(counter(&app, "integrate/bodies"), 1.0);
}

fn crate_box(app: &mut App, z: f32) -> Entity {
    app.world_mut()
        .spawn((
            Collider::cuboid(0.5, 0.5, 0.5),
            Position::new(0.0, 0.0, z),
            Velocity::default(),
        ))
        .id()
}

/// A stack of three boxes falls asleep as one island (one key for all three, in the same step),
/// and a push on the bottom box wakes the whole stack before the next step moves anything.
#[test]
fn a_stack_sleeps_and_wakes_as_one_island_within_one_step() {
    let mut app = sleepy_app();
    let stack: Vec<Entity> = (0..3)
        .map(|i| crate_box(&mut app, 0.5 + i as f32))
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
        let s = states(&app);
        let count = s.iter().filter(|s| s.asleep).count();
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
    assert!(states(&app).iter().all(|s| !s.asleep && s.island == 0));
}

/// Despawning the bottom box of a sleeping stack of three wakes the two above it (the middle one
/// lost a contact; the top one is in its island), and they fall: the top box ends at least
/// 0.9 m lower within a second.
#[test]
fn despawning_the_bottom_of_a_sleeping_stack_wakes_the_whole_island() {
    let mut app = sleepy_app();
    let stack: Vec<Entity> = (0..3)
        .map(|i| crate_box(&mut app, 0.5 + i as f32))
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
    let lower = ball(&mut app, Vec3::new(0.0, 0.0, 0.5));
    urto::step(app.world_mut(), 60).unwrap();
    assert!(asleep(&app, lower));
    // Slightly off-centre, so the lower ball is pushed sideways.
    ball(&mut app, Vec3::new(0.3, 0.0, 3.0));
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
        let b = ball(&mut app, Vec3::new(0.0, 0.0, 0.5));
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

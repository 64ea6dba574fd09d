//! Collisions through the whole plugin: the broad phase finds exactly the overlapping pairs,
//! impulses conserve momentum (and energy when elastic), restitution returns the right fraction,
//! and game code hears when collisions start and end; sensors in `sensors.rs`.

#[path = "../common/mod.rs"]
mod common;
mod sensors;

use bevy_app::{App, PluginGroup};
use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;
use common::rng::Rng;
use glam::Vec3;
use std::collections::BTreeSet;
use urto::geometry::Shape;
use urto::plugins::{BroadPhasePairs, ResponsePlugin};
use urto::prelude::*;

/// A frictionless ball, so that impacts exchange momentum along the normal only.
fn ball(app: &mut bevy_app::App, at: Vec3, v: Vec3, m: f32, e: f32) -> Entity {
    app.world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position(at),
            Velocity(v),
            Mass(m),
            Restitution(e),
            Friction(0.0),
        ))
        .id()
}

fn velocity(app: &bevy_app::App, e: Entity) -> Vec3 {
    app.world().get::<Velocity>(e).unwrap().0
}

#[test]
fn a_head_on_elastic_collision_conserves_momentum_and_energy() {
    let mut app = common::app();
    let (ma, mb) = (1.0, 3.0);
    let a = ball(
        &mut app,
        Vec3::new(-2.0, 0.0, 0.0),
        Vec3::new(4.0, 0.3, 0.0),
        ma,
        1.0,
    );
    let b = ball(
        &mut app,
        Vec3::new(2.0, 0.0, 0.1),
        Vec3::new(-2.0, 0.0, 0.0),
        mb,
        1.0,
    );
    let momentum = |app: &bevy_app::App| velocity(app, a) * ma + velocity(app, b) * mb;
    let spin = |app: &bevy_app::App, e: Entity| {
        app.world()
            .get::<AngularVelocity>(e)
            .map_or(Vec3::ZERO, |w| w.0)
    };
    // Kinetic energy, the balls' turning included (a solid ball's `I = 2/5 m r²`): the
    // contact's normal is where the balls meet, but its point, one for both, lies half the
    // sideways gap they still had at the step's start off each line of centres, so the
    // bounce turns them a little (0.16 and 0.05 rad/s here, 1.2e-4 of the energy).
    let energy = |app: &bevy_app::App| {
        let turning = |e: Entity, m: f32| 0.4 * m * 0.25 * spin(app, e).length_squared();
        0.5 * (ma * velocity(app, a).length_squared() + mb * velocity(app, b).length_squared())
            + 0.5 * (turning(a, ma) + turning(b, mb))
    };
    let (p0, e0) = (momentum(&app), energy(&app));
    urto::step(app.world_mut(), 120).unwrap();
    assert!((momentum(&app) - p0).length() < 1e-4 * p0.length().max(1.0));
    assert!(
        (energy(&app) / e0 - 1.0).abs() < 1e-4,
        "{} vs {e0}",
        energy(&app)
    );
    assert!(velocity(&app, a).x < 0.0, "the light ball bounced back");
    // The turn the one contact point gives them stays under 3 % of a roll at the closing speed.
    let closing = 6.0 / 0.5;
    for e in [a, b] {
        assert!(spin(&app, e).length() < 0.03 * closing, "{}", spin(&app, e));
    }
}

#[test]
fn restitution_returns_its_fraction_of_the_closing_speed() {
    for e in [0.0, 0.25, 0.5, 0.9] {
        let mut app = common::app();
        let a = ball(
            &mut app,
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0),
            2.0,
            e,
        );
        let b = ball(
            &mut app,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(-1.0, 0.0, 0.0),
            1.0,
            e,
        );
        urto::step(app.world_mut(), 60).unwrap();
        let separating = velocity(&app, b).x - velocity(&app, a).x;
        assert!((separating - e * 4.0).abs() < 1e-4, "e = {e}: {separating}");
    }
}

#[test]
fn many_colliding_balls_conserve_total_momentum() {
    let mut app = common::app();
    let mut rng = Rng::new(11);
    let balls: Vec<(Entity, f32)> = (0..60)
        .map(|_| {
            let m = rng.range(0.5, 4.0);
            let e = ball(
                &mut app,
                rng.in_ball(4.0),
                rng.in_ball(3.0),
                m,
                rng.range(0.2, 1.0),
            );
            (e, m)
        })
        .collect();
    let total = |app: &bevy_app::App| {
        balls
            .iter()
            .map(|(e, m)| velocity(app, *e) * *m)
            .sum::<Vec3>()
    };
    let p0 = total(&app);
    let mut contacts = 0.0;
    for _ in 0..120 {
        urto::step(app.world_mut(), 1).unwrap();
        contacts += app
            .world()
            .resource::<PhysicsStats>()
            .counter("narrow_phase/contacts")
            .unwrap_or(0.0);
    }
    assert!(
        contacts > 20.0,
        "the scene must actually collide ({contacts} contacts)"
    );
    assert!(
        (total(&app) - p0).length() < 1e-3,
        "{} vs {p0}",
        total(&app)
    );
}

#[test]
fn a_ball_dropped_on_the_ground_rebounds_with_restitution() {
    let mut app = common::legacy_app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static, Restitution(0.6)));
    let b = ball(&mut app, Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 1.0, 0.6);
    let mut before = 0.0f32;
    for _ in 0..120 {
        let v = velocity(&app, b).z;
        urto::step(app.world_mut(), 1).unwrap();
        let after = velocity(&app, b).z;
        if v < 0.0 && after > 0.0 {
            // Integration runs before response: the ball hit the ground at v - g dt.
            before = v - 9.8 / 60.0;
            assert!((after / -before - 0.6).abs() < 1e-3, "{after} / {before}");
            break;
        }
    }
    assert!(before < -5.0, "the ball must have hit the ground fast");
}

#[test]
fn collision_messages_report_each_touch_once() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let ground = app
        .world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static, Restitution(0.8)))
        .id();
    let b = ball(&mut app, Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO, 1.0, 0.8);
    let (mut started, mut ended) = (0, 0);
    let mut cursor_s = app
        .world()
        .resource::<Messages<CollisionStarted>>()
        .get_cursor();
    let mut cursor_e = app
        .world()
        .resource::<Messages<CollisionEnded>>()
        .get_cursor();
    for _ in 0..150 {
        urto::step(app.world_mut(), 1).unwrap();
        let w = app.world();
        for m in cursor_s.read(w.resource::<Messages<CollisionStarted>>()) {
            assert_eq!((m.a.min(m.b), m.a.max(m.b)), (ground.min(b), ground.max(b)));
            started += 1;
            assert_eq!(started, ended + 1, "a start must follow an end");
        }
        for _ in cursor_e.read(w.resource::<Messages<CollisionEnded>>()) {
            ended += 1;
            assert_eq!(ended, started, "an end must follow a start");
        }
    }
    assert!(started >= 2, "the ball bounced at least twice: {started}");
}

/// Every pair the broad phase reports overlaps, and every overlapping pair with a moving body
/// is reported — while bodies move, spawn, despawn and get quarantined.
#[test]
fn broad_phase_pairs_equal_brute_force_under_churn() {
    // Without the response, bodies stay where the broad phase saw them, so its pairs can be
    // compared with the volumes the world holds after the step.
    let mut app = bevy_app::App::new();
    app.add_plugins(
        UrtoPlugins::default()
            .build()
            .disable::<ResponsePlugin>()
            .disable::<urto::plugins::SoftStepPlugin>(),
    );
    let mut rng = Rng::new(5);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    for _ in 0..40 {
        let h = Vec3::new(
            rng.range(0.2, 2.0),
            rng.range(0.2, 2.0),
            rng.range(0.2, 1.0),
        );
        app.world_mut().spawn((
            Collider::cuboid(h.x, h.y, h.z),
            Position(rng.in_ball(15.0)),
            Static,
        ));
    }
    let mut moving: Vec<Entity> = Vec::new();
    for step in 0..200 {
        if step % 3 == 0 {
            let shape = if rng.range(0.0, 1.0) < 0.5 {
                Collider::sphere(rng.range(0.2, 1.0))
            } else {
                Collider::cuboid(
                    rng.range(0.2, 1.0),
                    rng.range(0.2, 1.0),
                    rng.range(0.2, 1.0),
                )
            };
            let e = app
                .world_mut()
                .spawn((
                    shape,
                    Position(rng.in_ball(12.0)),
                    Velocity(rng.in_ball(6.0)),
                ))
                .id();
            moving.push(e);
        }
        if step % 7 == 0 && moving.len() > 4 {
            let victim = moving.remove(rng.below(moving.len()));
            app.world_mut().despawn(victim);
        }
        if step == 50 {
            app.world_mut().get_mut::<Position>(moving[1]).unwrap().0.x = f32::NAN;
        }
        urto::step(app.world_mut(), 1).unwrap();
        assert_eq!(
            reported_pairs(&mut app),
            brute_force_pairs(&mut app),
            "step {step}"
        );
    }
}

fn reported_pairs(app: &mut bevy_app::App) -> BTreeSet<(Entity, Entity)> {
    let pairs = &app.world().resource::<BroadPhasePairs>().pairs;
    let set: BTreeSet<_> = pairs.iter().map(|&(a, b)| (a.min(b), a.max(b))).collect();
    assert_eq!(set.len(), pairs.len(), "no pair twice");
    set
}

/// Every pair of a moving body with a body whose volume its own meets; a half-space (an
/// infinite volume) only where the body's volume has a corner below its plane.
fn brute_force_pairs(app: &mut bevy_app::App) -> BTreeSet<(Entity, Entity)> {
    let mut q = app.world_mut().query_filtered::<(
        Entity,
        &BoundingVolume,
        &Collider,
        &GlobalPose,
        Has<Velocity>,
        Has<Static>,
    ), Without<Quarantined>>();
    let bodies: Vec<_> = q
        .iter(app.world())
        .map(|(e, b, c, g, v, s)| {
            let plane = match &c.shape {
                Shape::HalfSpace(h) => Some((g.pose().rotation * h.normal, g.pose().translation)),
                _ => None,
            };
            (e, b.0, v && !s, plane)
        })
        .collect();
    let below = |(n, at): (Vec3, Vec3), b: &urto::bounding::Aabb| {
        (0..8).any(|k| {
            let corner = Vec3::select(
                glam::BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0),
                b.max,
                b.min,
            );
            n.dot(corner - at) <= 0.0
        })
    };
    let mut set = BTreeSet::new();
    for (i, (a, ba, ma, pa)) in bodies.iter().enumerate() {
        for (b, bb, mb, pb) in &bodies[i + 1..] {
            let meet = match (pa, pb) {
                (Some(p), None) => below(*p, bb),
                (None, Some(p)) => below(*p, ba),
                _ => ba.intersects(bb),
            };
            if (*ma || *mb) && meet {
                set.insert(((*a).min(*b), (*a).max(*b)));
            }
        }
    }
    set
}

/// Starts and ends read from the messages since `cursor`s were made, as `(a, b)` with `a < b`.
struct Heard {
    started: bevy_ecs::message::MessageCursor<CollisionStarted>,
    ended: bevy_ecs::message::MessageCursor<CollisionEnded>,
}

impl Heard {
    fn new(app: &bevy_app::App) -> Self {
        let w = app.world();
        Self {
            started: w.resource::<Messages<CollisionStarted>>().get_cursor(),
            ended: w.resource::<Messages<CollisionEnded>>().get_cursor(),
        }
    }

    fn read(&mut self, app: &bevy_app::App) -> [Vec<(Entity, Entity)>; 2] {
        let w = app.world();
        let s = self
            .started
            .read(w.resource::<Messages<CollisionStarted>>());
        let started = s.map(|m| (m.a, m.b)).collect();
        let e = self.ended.read(w.resource::<Messages<CollisionEnded>>());
        [started, e.map(|m| (m.a, m.b)).collect()]
    }
}

fn ordered(a: Entity, b: Entity) -> (Entity, Entity) {
    (a.min(b), a.max(b))
}

/// The starts read since `cursor`, each with its contact.
fn starts_with_contact(
    app: &bevy_app::App,
    cursor: &mut bevy_ecs::message::MessageCursor<CollisionStarted>,
) -> Vec<CollisionStarted> {
    let messages = app.world().resource::<Messages<CollisionStarted>>();
    cursor.read(messages).copied().collect()
}

#[test]
fn a_dropped_ball_reports_its_impact_speed_within_2_percent_and_its_normal_within_1e_4() {
    let (c, (b, ground)) = dropped_ball_contact(common::app());
    let (mass, v) = (DROP_MASS, (2.0 * 9.8 * DROP_HEIGHT).sqrt());
    assert_eq!((c.collider, c.other_collider), (b, ground));
    // Restitution 0: the one point's push in the first substep stops the ball (m v).
    assert!((c.normal_impulse / (mass * v) - 1.0).abs() < 0.03, "{c:?}");
    assert!(c.manifold.normal.dot(-Vec3::Z) > 1.0 - 1e-4, "{c:?}");
    assert!(
        (c.impact_speed / v - 1.0).abs() < 0.02,
        "{} vs {v}",
        c.impact_speed
    );
    assert!(!c.manifold.is_empty());
    for p in c.manifold.points() {
        assert!(
            (p.point.truncate() - glam::Vec2::new(0.3, -0.2)).length() < 1e-3,
            "{p:?}"
        );
        // Detected up to one step's fall (v dt) before it touched: midway, at most half of it.
        assert!(p.point.z.abs() < 0.5 * v / 60.0, "{p:?}");
    }
}

#[test]
fn the_lectures_pipeline_reports_the_impact_speed_within_3_percent_and_its_impulse_within_5() {
    // Detection after the fall, on the integrator's discrete fall: the speed is within one
    // step's g dt (2.75 % here) of √(2gh), and the response stops the ball (restitution 0).
    let (c, (b, ground)) = dropped_ball_contact(common::legacy_app());
    let (mass, v) = (DROP_MASS, (2.0 * 9.8 * DROP_HEIGHT).sqrt());
    assert_eq!((c.collider, c.other_collider), (b, ground));
    assert!(c.manifold.normal.dot(-Vec3::Z) > 1.0 - 1e-4, "{c:?}");
    let speed = c.impact_speed / v - 1.0;
    assert!(speed.abs() < 0.03, "{} vs {v}", c.impact_speed);
    let push = c.normal_impulse / (mass * c.impact_speed) - 1.0;
    assert!(push.abs() < 0.05, "{c:?}");
}

const DROP_MASS: f32 = 2.0;
const DROP_HEIGHT: f32 = 1.8;

/// The one collision start of a 2 kg ball dropped 1.8 m onto a floor with restitution 0, as
/// the ball sees it; and the ball and the floor.
fn dropped_ball_contact(mut app: App) -> (ContactData, (Entity, Entity)) {
    app.insert_resource(Gravity::EARTH_Z_UP);
    let ground = app
        .world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static, Restitution(0.0)))
        .id();
    let b = ball(
        &mut app,
        Vec3::new(0.3, -0.2, 0.5 + DROP_HEIGHT),
        Vec3::ZERO,
        DROP_MASS,
        0.0,
    );
    let mut cursor = app
        .world()
        .resource::<Messages<CollisionStarted>>()
        .get_cursor();
    let mut starts = Vec::new();
    for _ in 0..60 {
        urto::step(app.world_mut(), 1).unwrap();
        starts.extend(starts_with_contact(&app, &mut cursor));
    }
    assert_eq!(starts.len(), 1, "{starts:?}");
    let stranger = starts[0].contact_from(Entity::PLACEHOLDER);
    assert!(stranger.is_none(), "not one of the pair");
    let c = starts[0]
        .contact_from(b)
        .expect("a contact, not a sensor overlap");
    (c, (b, ground))
}

#[test]
fn a_compound_reports_the_part_that_hit_and_both_sides_see_one_contact_normal_within_1e_6() {
    #[derive(Resource, Default)]
    struct Seen(Vec<CollisionStart>);
    let mut app = common::app();
    app.init_resource::<Seen>();
    app.world_mut()
        .add_observer(|e: On<CollisionStart>, mut seen: ResMut<Seen>| seen.0.push(*e));
    // A dumbbell flying along +x, its lower bell leading: the bell is what hits the wall.
    let dumbbell = app
        .world_mut()
        .spawn((
            Position::new(-3.0, 0.0, 0.0),
            Velocity(Vec3::new(4.0, 0.0, 0.0)),
            CollisionEventsEnabled,
        ))
        .id();
    let spawn_bell = |app: &mut bevy_app::App, at: Vec3| {
        let part = (Collider::sphere(0.3), Position(at), ChildOf(dumbbell));
        app.world_mut().spawn(part).id()
    };
    let leading = spawn_bell(&mut app, Vec3::new(0.5, 0.0, 0.0));
    spawn_bell(&mut app, Vec3::new(-0.5, 0.0, 0.0));
    let wall = app
        .world_mut()
        .spawn((
            Collider::cuboid(0.1, 2.0, 2.0),
            Position::new(0.0, 0.0, 0.0),
            Velocity::default(),
            Mass(50.0),
            CollisionEventsEnabled,
        ))
        .id();
    // And a sensor the dumbbell starts in: an overlap, no contact.
    let zone = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::new(-3.0, 0.0, 0.0),
            Static,
            Sensor,
        ))
        .id();
    urto::step(app.world_mut(), 60).unwrap();
    let seen = &app.world().resource::<Seen>().0;
    let between = |entity: Entity, other: Entity| -> Vec<&CollisionStart> {
        let pair = |e: &&CollisionStart| e.entity == entity && e.other == other;
        seen.iter().filter(pair).collect()
    };
    let (from_bell, from_wall) = (between(dumbbell, wall), between(wall, dumbbell));
    assert_eq!((from_bell.len(), from_wall.len()), (1, 1), "{seen:?}");
    let sensed = between(dumbbell, zone);
    // (Entered again after the bounce off the heavy wall.)
    assert!(!sensed.is_empty(), "{seen:?}");
    assert!(sensed.iter().all(|e| e.contact.is_none()), "{seen:?}");
    let (c, w) = (from_bell[0].contact.unwrap(), from_wall[0].contact.unwrap());
    assert_eq!((c.collider, c.other_collider), (leading, wall));
    assert_eq!((w.collider, w.other_collider), (wall, leading));
    assert!((c.manifold.normal - Vec3::X).length() < 1e-6, "{c:?}");
    assert!((w.manifold.normal + Vec3::X).length() < 1e-6, "{w:?}");
    assert!((c.impact_speed - 4.0).abs() < 1e-3 * 4.0, "{c:?}");
    assert_eq!(
        (c.impact_speed, c.normal_impulse),
        (w.impact_speed, w.normal_impulse)
    );
}

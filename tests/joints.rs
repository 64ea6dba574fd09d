//! Joints through the ECS: a pendulum's period against `2π√(L/g)`, a motor's speed, what a
//! joint holds against `m g`, breaking, jointed bodies that do not collide unless asked, that
//! sleep and wake together, bad joints quarantined without harm to their bodies, and results
//! that do not depend on the joints' archetypes.

mod common;

use bevy_app::App;
use bevy_ecs::prelude::*;
use glam::Vec3;
use urto::plugins::Contacts;
use urto::prelude::*;

fn app() -> App {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app
}

fn get<T: Component + Copy>(app: &App, e: Entity) -> T {
    *app.world().get::<T>(e).expect("component present")
}

/// A 1 kg ball (whatever its size), so that loads read as multiples of `g`.
fn ball(app: &mut App, at: Vec3, radius: f32) -> Entity {
    let body = (Collider::sphere(radius), Position(at), Velocity::default());
    app.world_mut().spawn((body, Mass(1.0))).id()
}

/// The mean period of `x(t)` from its upward zero crossings, at 60 Hz.
fn period(xs: &[f32]) -> f32 {
    let crossings: Vec<f32> = xs
        .windows(2)
        .enumerate()
        .filter(|(_, w)| w[0] < 0.0 && w[1] >= 0.0)
        .map(|(i, w)| (i as f32 + w[0] / (w[0] - w[1])) / 60.0)
        .collect();
    assert!(crossings.len() >= 3, "{} crossings", crossings.len());
    (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f32
}

#[test]
fn a_ball_hung_from_the_world_on_a_2_m_ball_joint_swings_at_2_pi_root_l_over_g_within_1_percent() {
    let mut app = app();
    let (length, start) = (2.0f32, 4f32.to_radians());
    let pivot = Vec3::new(0.0, 0.0, 10.0);
    let at = pivot + Vec3::new(start.sin(), 0.0, -start.cos()) * length;
    let bob = ball(&mut app, at, 0.05);
    let joint = Joint::spherical(bob, JointEnd::World)
        .with_anchors(Rotation::default().0.inverse() * (pivot - at), pivot);
    app.world_mut().spawn(joint);
    let mut xs = Vec::new();
    for _ in 0..600 {
        urto::step(app.world_mut(), 1).unwrap();
        xs.push(get::<Position>(&app, bob).0.x);
    }
    let expected = std::f32::consts::TAU * (length / 9.81).sqrt();
    let t = period(&xs);
    assert!(
        (t / expected - 1.0).abs() < 0.01,
        "{t} s against {expected} s"
    );
}

#[test]
fn a_hinge_motor_spins_a_wheel_at_its_target_within_2_percent_and_holds_what_it_drives() {
    let mut app = app();
    let axle = app
        .world_mut()
        .spawn((Collider::sphere(0.05), Position::new(0.0, 0.0, 3.0), Static))
        .id();
    let wheel = app
        .world_mut()
        .spawn((
            Collider::cuboid(0.4, 0.4, 0.05),
            Position::new(0.0, 0.0, 3.0),
            Velocity::default(),
            Mass(1.0),
            AngularDrag(0.5),
        ))
        .id();
    let motor = JointMotor::velocity(4.0, 20.0);
    let joint = app
        .world_mut()
        .spawn(
            Joint::revolute(axle, wheel)
                .with_axis(Vec3::Z)
                .with_motor(motor),
        )
        .id();
    urto::step(app.world_mut(), 180).unwrap();
    let w = get::<AngularVelocity>(&app, wheel).0;
    assert!((w.z / 4.0 - 1.0).abs() < 0.02, "{w}");
    assert!(
        w.x.abs() < 1e-3 && w.y.abs() < 1e-3,
        "turned off the axis: {w}"
    );
    // The joint carries the wheel's weight: m g = 9.81 N (within 2 %).
    let load = get::<JointLoad>(&app, joint);
    assert!((load.force / 9.81 - 1.0).abs() < 0.02, "{load:?}");
    let p = get::<Position>(&app, wheel).0;
    assert!(
        (p - Vec3::new(0.0, 0.0, 3.0)).length() < 1e-3,
        "the wheel sagged to {p}"
    );
}

#[test]
fn a_position_motor_holding_an_arm_level_reports_its_torque_as_m_g_l_within_2_percent() {
    // A 2 kg ball on a massless 1.5 m lever hinged about y at a static post: the motor holds
    // the lever level, so at rest it applies m g L about the hinge (gravity pulls the ball
    // down, turning it about +y: the motor's torque is the opposite, negative).
    let mut app = app();
    let (mass, lever) = (2.0f32, 1.5f32);
    let post = app
        .world_mut()
        .spawn((Collider::sphere(0.05), Position::new(0.0, 0.0, 3.0), Static))
        .id();
    let arm = ball(&mut app, Vec3::new(lever, 0.0, 3.0), 0.1);
    app.world_mut().entity_mut(arm).insert(Mass(mass));
    let joint = app
        .world_mut()
        .spawn(
            Joint::revolute(post, arm)
                .with_axis(Vec3::Y)
                .with_anchors(Vec3::ZERO, Vec3::new(-lever, 0.0, 0.0))
                .with_motor(JointMotor::position(0.0, 4.0, 1.0, 500.0)),
        )
        .id();
    urto::step(app.world_mut(), 240).unwrap();
    let load = get::<JointLoad>(&app, joint);
    let expected = mass * 9.81 * lever;
    assert!(
        (-load.motor / expected - 1.0).abs() < 0.02,
        "{load:?} against {expected} N m"
    );
    let sag = 3.0 - get::<Position>(&app, arm).0.z;
    assert!(sag.abs() < 0.05, "the arm sagged {sag} m");
}

#[test]
fn a_joint_breaks_above_its_force_with_a_message_and_holds_below_it() {
    let mut app = app();
    let weak = ball(&mut app, Vec3::new(0.0, 0.0, 5.0), 0.2);
    let strong = ball(&mut app, Vec3::new(3.0, 0.0, 5.0), 0.2);
    let hang = |b: Entity, x: f32, limit: f32| {
        Joint::rope(b, JointEnd::World, 1.0)
            .with_anchors(Vec3::ZERO, Vec3::new(x, 0.0, 6.0))
            .breakable(limit, f32::INFINITY)
    };
    let weak_joint = app.world_mut().spawn(hang(weak, 0.0, 5.0)).id();
    app.world_mut().spawn(hang(strong, 3.0, 50.0));
    let mut cursor = app.world().resource::<Messages<JointBroken>>().get_cursor();
    let mut broken = Vec::new();
    for _ in 0..120 {
        urto::step(app.world_mut(), 1).unwrap();
        let messages = app.world().resource::<Messages<JointBroken>>();
        broken.extend(cursor.read(messages).copied());
    }
    assert_eq!(broken.len(), 1, "{broken:?}");
    assert_eq!(broken[0].joint, weak_joint);
    assert!(broken[0].force > 5.0);
    assert!(app.world().get::<JointDisabled>(weak_joint).is_some());
    assert!(get::<Position>(&app, weak).0.z < 0.0, "the weak one fell");
    let held = get::<Position>(&app, strong).0.z;
    assert!((held - 5.0).abs() < 0.01, "the strong one hangs at {held}");
}

/// Two 1 m boxes overlapping by half, on a ball joint at their shared centre, resting on the
/// ground: how far apart they end.
fn overlapping_pair(collide: bool) -> (f32, usize) {
    let mut app = app();
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    let unit_box = |app: &mut App, at: Vec3| {
        let body = (
            Collider::cuboid(0.5, 0.5, 0.5),
            Position(at),
            Velocity::default(),
        );
        app.world_mut().spawn(body).id()
    };
    let a = unit_box(&mut app, Vec3::new(0.0, 0.0, 0.5));
    let b = unit_box(&mut app, Vec3::new(0.5, 0.0, 0.5));
    let mut joint =
        Joint::spherical(a, b).with_anchors(Vec3::new(0.25, 0.0, 0.0), Vec3::new(-0.25, 0.0, 0.0));
    if collide {
        joint = joint.with_collisions();
    }
    app.world_mut().spawn(joint);
    urto::step(app.world_mut(), 1).unwrap();
    let touching = app
        .world()
        .resource::<Contacts>()
        .pairs
        .iter()
        .filter(|p| (p.a == a && p.b == b) || (p.a == b && p.b == a))
        .count();
    urto::step(app.world_mut(), 59).unwrap();
    let gap = (get::<Position>(&app, b).0 - get::<Position>(&app, a).0).length();
    (gap, touching)
}

#[test]
fn jointed_bodies_do_not_collide_unless_the_joint_lets_them() {
    let (gap, touching) = overlapping_pair(false);
    assert_eq!(touching, 0);
    assert!((gap - 0.5).abs() < 0.01, "apart by {gap}");
    let (_, touching) = overlapping_pair(true);
    assert_eq!(touching, 1, "with_collisions: the pair is tested");
}

#[test]
fn a_jointed_pair_falls_asleep_together_and_a_push_on_one_wakes_both() {
    let mut app = app();
    let top = ball(&mut app, Vec3::new(0.0, 0.0, 4.0), 0.2);
    let bottom = ball(&mut app, Vec3::new(0.0, 0.0, 3.0), 0.2);
    let world = app.world_mut();
    world.spawn(
        Joint::rod(top, JointEnd::World, 1.0).with_anchors(Vec3::ZERO, Vec3::new(0.0, 0.0, 5.0)),
    );
    world.spawn(Joint::rod(top, bottom, 1.0));
    urto::step(app.world_mut(), 240).unwrap();
    let asleep = |app: &App, e: Entity| app.world().get::<Sleeping>(e).is_some();
    assert!(
        asleep(&app, top) && asleep(&app, bottom),
        "both hang still and sleep"
    );
    app.world_mut().get_mut::<Velocity>(bottom).unwrap().0 = Vec3::new(2.0, 0.0, 0.0);
    urto::step(app.world_mut(), 1).unwrap();
    assert!(
        !asleep(&app, top) && !asleep(&app, bottom),
        "a push on one wakes both"
    );
    // The rods are vertical, so the top feels the push only as the pendulum swings.
    for _ in 0..30 {
        urto::step(app.world_mut(), 1).unwrap();
        eprintln!(
            "top {} {:?} {}",
            asleep(&app, top),
            app.world().get::<SleepState>(top),
            get::<Velocity>(&app, top).0
        );
    }
    let top_moved = get::<Position>(&app, top).0.x.abs();
    assert!(top_moved > 0.01, "the top moved {top_moved} m");
}

#[test]
fn bad_joints_are_quarantined_and_a_joint_to_a_bad_body_leaves_the_good_one_finite() {
    let mut app = app();
    let good = ball(&mut app, Vec3::new(0.0, 0.0, 5.0), 0.2);
    let other = ball(&mut app, Vec3::new(2.0, 0.0, 5.0), 0.2);
    let gone = ball(&mut app, Vec3::new(4.0, 0.0, 5.0), 0.2);
    let poisoned = app
        .world_mut()
        .spawn((
            Collider::sphere(0.2),
            Position::new(f32::NAN, 0.0, 5.0),
            Velocity::default(),
        ))
        .id();
    let world = app.world_mut();
    let bad = [
        world
            .spawn(Joint::spherical(good, other).with_anchors(Vec3::NAN, Vec3::ZERO))
            .id(),
        world
            .spawn(Joint::revolute(good, other).with_limits(1.0, -1.0))
            .id(),
        world.spawn(Joint::spherical(good, good)).id(),
        world.spawn(Joint::rope(good, gone, 1.0)).id(),
    ];
    world.spawn(Joint::rod(other, poisoned, 1.0));
    world.despawn(gone);
    urto::step(app.world_mut(), 60).unwrap();
    for joint in bad {
        assert!(app.world().get::<Quarantined>(joint).is_some(), "{joint}");
    }
    // Free fall for a second: the joints held nothing, and nothing turned NaN.
    for e in [good, other] {
        let p = get::<Position>(&app, e).0;
        assert!(p.is_finite(), "{p}");
        assert!((p.z - (5.0 - 0.5 * 9.81)).abs() < 0.1, "{e} at {p}");
    }
}

/// A 6-link rod chain swinging from the world for 2 s, its joints spawned with `marker` on
/// every other one: the links' final positions.
fn swinging_chain(marker: bool) -> Vec<Vec3> {
    #[derive(Component)]
    struct Gameplay;
    let mut app = app();
    let links: Vec<Entity> = (0..6)
        .map(|i| ball(&mut app, Vec3::new(0.5 * (i + 1) as f32, 0.0, 5.0), 0.1))
        .collect();
    let world = app.world_mut();
    let mut previous = JointEnd::World;
    for (i, &link) in links.iter().enumerate() {
        let anchor = match previous {
            JointEnd::World => Vec3::new(0.0, 0.0, 5.0),
            _ => Vec3::ZERO,
        };
        let joint = Joint::rod(link, previous, 0.5).with_anchors(Vec3::ZERO, anchor);
        let mut e = world.spawn(joint);
        if marker && i % 2 == 1 {
            e.insert(Gameplay);
        }
        previous = JointEnd::Body(link);
    }
    urto::step(app.world_mut(), 120).unwrap();
    links.iter().map(|&e| get::<Position>(&app, e).0).collect()
}

#[test]
fn a_marker_on_some_joints_changes_no_bit_of_a_swinging_chain() {
    assert_eq!(swinging_chain(false), swinging_chain(true));
}

/// A 0.1 m ball thrown at 40 m/s through a 4 cm static wall it is tied to by a 3 m rope: where
/// it is after 4 steps (continuous collision sweeps it, 0.67 m a step).
fn thrown_through_its_wall(collide: bool) -> f32 {
    let mut app = app();
    app.world_mut().remove_resource::<Gravity>();
    let wall = app
        .world_mut()
        .spawn((
            Collider::cuboid(0.02, 2.0, 2.0),
            Position::new(0.0, 0.0, 5.0),
            Static,
        ))
        .id();
    let ball = ball(&mut app, Vec3::new(-1.0, 0.0, 5.0), 0.1);
    app.world_mut()
        .entity_mut(ball)
        .insert(Velocity::new(40.0, 0.0, 0.0));
    let mut rope = Joint::rope(ball, wall, 3.0);
    if collide {
        rope = rope.with_collisions();
    }
    app.world_mut().spawn(rope);
    urto::step(app.world_mut(), 4).unwrap();
    get::<Position>(&app, ball).0.x
}

#[test]
fn a_fast_ball_passes_through_the_wall_it_is_jointed_to_and_bounces_off_it_with_collisions() {
    let through = thrown_through_its_wall(false);
    assert!(through > 0.5, "stopped at x = {through}");
    let bounced = thrown_through_its_wall(true);
    assert!(bounced < 0.0, "passed to x = {bounced}");
}

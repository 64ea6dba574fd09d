//! What a body weighs and what pushes it, through the ECS: mass from the colliders' volume at a
//! density (by default 1 kg/m³), a `Mass` that overrides it and comes undone, impulses (linear,
//! at a point, angular, on a sleeper, bad ones), a per-body gravity scale, and a cone standing
//! on its base or falling over from its apex, and a 2D game's locked stack coming to rest.

mod common;

use bevy_app::App;
use bevy_ecs::prelude::*;
use glam::Vec3;
use urto::prelude::*;

fn get<T: Component + Copy>(app: &App, e: Entity) -> T {
    *app.world().get::<T>(e).expect("component present")
}

#[test]
fn density_gives_a_ball_a_box_and_a_compound_the_mass_of_their_volume_within_1e_5() {
    use bevy_ecs::hierarchy::ChildOf;
    use std::f32::consts::PI;
    let mut app = common::app();
    let world = app.world_mut();
    let ball = world
        .spawn((
            Collider::sphere(0.5),
            Position::new(0.0, 0.0, 5.0),
            Velocity::default(),
            Density(1000.0),
        ))
        .id();
    let crate_box = world
        .spawn((
            Collider::cuboid(0.5, 1.0, 1.5),
            Position::new(5.0, 0.0, 5.0),
            Velocity::default(),
            Density(2.0),
        ))
        .id();
    let root = world
        .spawn((
            Collider::cuboid(0.5, 0.5, 0.5),
            Position::new(-5.0, 0.0, 5.0),
            Velocity::default(),
            Density(10.0),
        ))
        .id();
    world.spawn((
        Collider::sphere(0.25),
        Position::new(1.0, 0.0, 0.0),
        ChildOf(root),
    ));
    let bad = world
        .spawn((
            Collider::sphere(0.5),
            Position::new(0.0, 5.0, 5.0),
            Velocity::default(),
            Density(f32::NAN),
        ))
        .id();
    let kinematic = world
        .spawn((
            Collider::sphere(0.5),
            Position::new(0.0, -5.0, 5.0),
            Velocity::default(),
            Mass::INFINITE,
            Density(1000.0),
        ))
        .id();
    urto::step(app.world_mut(), 2).unwrap();
    let mass = |e| app.world().get::<ComputedMass>(e).unwrap().value();
    let close = |a: f32, b: f32| ((a - b) / b).abs() < 1e-5;
    let ball_mass = 1000.0 * 4.0 / 3.0 * PI * 0.125;
    assert!(close(mass(ball), ball_mass), "{}", mass(ball));
    // The inertia follows the new mass: 2/5 m r².
    let inertia = app.world().get::<Inertia>(ball).unwrap().principal;
    assert!(close(inertia.x, 0.4 * ball_mass * 0.25), "{inertia}");
    assert!(close(mass(crate_box), 2.0 * 1.0 * 2.0 * 3.0));
    let compound = 10.0 * (1.0 + 4.0 / 3.0 * PI * 0.25f32.powi(3));
    assert!(close(mass(root), compound), "{} vs {compound}", mass(root));
    // A NaN density is reported and the default one used.
    assert!(close(mass(bad), DEFAULT_DENSITY * 4.0 / 3.0 * PI * 0.125));
    assert!(mass(kinematic).is_infinite());
    assert!(app.world().get::<Quarantined>(bad).is_none());
}

#[test]
fn a_body_weighs_its_volume_by_default_a_given_mass_wins_and_removing_it_restores_within_1e_5() {
    use std::f32::consts::PI;
    let mut app = common::app();
    let world = app.world_mut();
    let spawn = |world: &mut bevy_ecs::world::World, x: f32| {
        let at = Position::new(x, 0.0, 5.0);
        world
            .spawn((Collider::sphere(2.0), at, Velocity::default()))
            .id()
    };
    let boulder = spawn(world, 0.0);
    let pebble = world
        .spawn((
            Collider::sphere(0.1),
            Position::new(9.0, 0.0, 5.0),
            Velocity::default(),
        ))
        .id();
    let given = spawn(world, -9.0);
    world.entity_mut(given).insert((Mass(3.0), Density(500.0)));
    let no_volume = world
        .spawn((Position::new(0.0, 9.0, 5.0), Velocity::default()))
        .id();
    urto::step(app.world_mut(), 1).unwrap();
    let mass = |app: &bevy_app::App, e| app.world().get::<ComputedMass>(e).unwrap().value();
    let inertia = |app: &bevy_app::App, e| app.world().get::<Inertia>(e).unwrap().principal.x;
    let close = |a: f32, b: f32| ((a - b) / b).abs() < 1e-5;
    let ball = |r: f32| DEFAULT_DENSITY * 4.0 / 3.0 * PI * r.powi(3);
    assert!(
        close(mass(&app, boulder), ball(2.0)),
        "{}",
        mass(&app, boulder)
    );
    assert!(close(mass(&app, pebble), ball(0.1)));
    assert!(close(mass(&app, given), 3.0));
    assert!(close(inertia(&app, given), 0.4 * 3.0 * 4.0));
    assert_eq!(mass(&app, no_volume), 1.0);
    // The mass set by the game goes: the density it also has takes over, inertia too.
    app.world_mut().entity_mut(given).remove::<Mass>();
    urto::step(app.world_mut(), 1).unwrap();
    let from_density = 500.0 * ball(2.0) / DEFAULT_DENSITY;
    assert!(
        close(mass(&app, given), from_density),
        "{}",
        mass(&app, given)
    );
    assert!(close(inertia(&app, given), 0.4 * from_density * 4.0));
    // And without the density, the default one.
    app.world_mut().entity_mut(given).remove::<Density>();
    urto::step(app.world_mut(), 1).unwrap();
    assert!(close(mass(&app, given), ball(2.0)));
    // 20 times the radius, 8,000 times the mass.
    assert!(close(mass(&app, boulder) / mass(&app, pebble), 8000.0));
}

#[test]
fn removing_a_collider_from_a_part_or_the_body_reweighs_it_within_1e_5() {
    // A probe found the mass, centre of mass and inertia kept from before the removal.
    use bevy_ecs::hierarchy::ChildOf;
    use std::f32::consts::PI;
    let mut app = common::app();
    let world = app.world_mut();
    let root = world
        .spawn((
            Collider::cuboid(0.5, 0.5, 0.5),
            Position::new(0.0, 0.0, 5.0),
            Velocity::default(),
            Density(2.0),
        ))
        .id();
    let part = world
        .spawn((
            Collider::sphere(0.25),
            Position::new(1.0, 0.0, 0.0),
            ChildOf(root),
        ))
        .id();
    urto::step(app.world_mut(), 1).unwrap();
    let mass = |app: &App| get::<ComputedMass>(app, root).value();
    let close = |a: f32, b: f32| (a - b).abs() <= 1e-5 * b.abs().max(1.0);
    let ball = 2.0 * 4.0 / 3.0 * PI * 0.25f32.powi(3);
    assert!(close(mass(&app), 2.0 + ball), "{}", mass(&app));
    app.world_mut().entity_mut(part).remove::<Collider>();
    urto::step(app.world_mut(), 1).unwrap();
    let inertia: Inertia = get(&app, root);
    assert!(close(mass(&app), 2.0), "{}", mass(&app));
    assert!(close(inertia.local_center_of_mass.length(), 0.0));
    // A cube of 2 kg and side 1: m (1 + 1) / 12 about each axis.
    assert!(close(inertia.principal.x, 2.0 / 6.0), "{inertia:?}");
    // Put back on the part, taken off the body: the ball alone, its centre 1 m out.
    app.world_mut()
        .entity_mut(part)
        .insert(Collider::sphere(0.25));
    app.world_mut().entity_mut(root).remove::<Collider>();
    urto::step(app.world_mut(), 1).unwrap();
    let inertia: Inertia = get(&app, root);
    assert!(close(mass(&app), ball), "{}", mass(&app));
    assert!(close(inertia.local_center_of_mass.x, 1.0), "{inertia:?}");
    // Without any collider: the default mass, and nothing to turn (infinite inertia).
    app.world_mut().entity_mut(part).remove::<Collider>();
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(mass(&app), 1.0);
    assert!(get::<Inertia>(&app, root).principal.x.is_infinite());
}

/// A ball of radius 0.5 and `mass` kg (I = 0.1 m kg m²) at `at`.
fn ball(app: &mut App, at: Vec3, mass: f32) -> Entity {
    let body = (Collider::sphere(0.5), Position(at), Velocity::default());
    app.world_mut().spawn((body, Mass(mass))).id()
}

#[test]
fn an_impulse_changes_velocity_by_j_over_m_and_spin_by_r_cross_j_over_i_within_1e_6_relative() {
    let mut app = common::app();
    let (m, dt) = (2.0, 1.0 / 60.0);
    let through = ball(&mut app, Vec3::ZERO, m);
    let at_point = ball(&mut app, Vec3::new(5.0, 0.0, 0.0), m);
    let locked = ball(&mut app, Vec3::new(10.0, 0.0, 0.0), m);
    let spun = ball(&mut app, Vec3::new(15.0, 0.0, 0.0), m);
    let world = app.world_mut();
    world
        .entity_mut(through)
        .insert(Impulse::new(Vec3::X * 4.0));
    // 4 N·s along x, 0.5 m above the centre: 2 N·m·s about +y.
    let mut shove = Impulse::default();
    shove.add_at_point(Vec3::X * 4.0, Vec3::new(5.0, 0.0, 0.5));
    world.entity_mut(at_point).insert(shove);
    let mut shove_locked = Impulse::default();
    shove_locked.add_at_point(Vec3::X * 4.0, Vec3::new(10.0, 0.0, 0.5));
    world
        .entity_mut(locked)
        .insert((shove_locked, LockedAxes::ROTATION_LOCKED));
    let mut twist = Impulse::default();
    twist.add_angular(Vec3::Z * 0.3);
    world.entity_mut(spun).insert(twist);
    urto::step(app.world_mut(), 1).unwrap();
    let close = |a: Vec3, b: Vec3| (a - b).length() <= 1e-6 * b.length().max(1.0);
    let v = |e| get::<Velocity>(&app, e).0;
    let w = |e| get::<AngularVelocity>(&app, e).0;
    let i = 0.1 * m;
    assert!(close(v(through), Vec3::X * 2.0), "{}", v(through));
    assert!(close(w(through), Vec3::ZERO));
    assert!(close(get::<Position>(&app, through).0, Vec3::X * 2.0 * dt));
    assert!(close(v(at_point), Vec3::X * 2.0));
    assert!(close(w(at_point), Vec3::Y * 2.0 / i), "{}", w(at_point));
    assert!(close(v(locked), Vec3::X * 2.0) && w(locked) == Vec3::ZERO);
    assert!(close(w(spun), Vec3::Z * 0.3 / i) && v(spun) == Vec3::ZERO);
    // Spent: the next step leaves the velocities as they are.
    assert!(get::<Impulse>(&app, through).is_empty());
    urto::step(app.world_mut(), 1).unwrap();
    assert!(close(get::<Velocity>(&app, through).0, Vec3::X * 2.0));
}

#[test]
fn an_impulse_wakes_a_sleeper_kinematic_bodies_ignore_it_and_a_nan_one_is_quarantined() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    let sleeper = ball(&mut app, Vec3::new(0.0, 0.0, 0.5), 1.0);
    let kinematic = ball(&mut app, Vec3::new(5.0, 0.0, 3.0), 1.0);
    // Finite inertia, so only the infinite-mass rule keeps it from spinning.
    let inertia = Inertia::custom(Vec3::splat(0.1), glam::Quat::IDENTITY);
    app.world_mut()
        .entity_mut(kinematic)
        .insert((Mass::INFINITE, inertia));
    let bad = ball(&mut app, Vec3::new(-5.0, 0.0, 0.5), 1.0);
    urto::step(app.world_mut(), 120).unwrap();
    assert!(
        app.world().get::<Sleeping>(sleeper).is_some(),
        "asleep first"
    );
    let world = app.world_mut();
    world
        .entity_mut(sleeper)
        .insert(Impulse::new(Vec3::Z * 3.0));
    let mut kick = Impulse::new(Vec3::Z * 3.0);
    kick.add_angular(Vec3::X);
    world.entity_mut(kinematic).insert(kick);
    world
        .entity_mut(bad)
        .insert(Impulse::new(Vec3::new(f32::NAN, 0.0, 0.0)));
    urto::step(app.world_mut(), 1).unwrap();
    let up = get::<Velocity>(&app, sleeper).0.z;
    // 3 m/s up, less one step of gravity.
    assert!((up - (3.0 - 9.8 / 60.0)).abs() < 0.05, "{up}");
    assert!(app.world().get::<Sleeping>(sleeper).is_none());
    assert_eq!(get::<Velocity>(&app, kinematic).0, Vec3::ZERO);
    assert_eq!(get::<AngularVelocity>(&app, kinematic).0, Vec3::ZERO);
    assert!(app.world().get::<Quarantined>(bad).is_some());
}

#[test]
fn a_gravity_scale_of_half_falls_at_half_g_zero_floats_minus_one_rises_within_1e_4() {
    // Through the rigid-body solver and through the lecture's pipeline.
    gravity_scales_in(common::app());
    gravity_scales_in(common::legacy_app());
}

fn gravity_scales_in(mut app: App) {
    app.insert_resource(Gravity::EARTH_Z_UP);
    let scaled = |app: &mut App, x: f32, s: f32| {
        let b = ball(app, Vec3::new(x, 0.0, 50.0), 3.0);
        app.world_mut().entity_mut(b).insert(GravityScale(s));
        b
    };
    let (half, none, up) = (
        scaled(&mut app, 0.0, 0.5),
        scaled(&mut app, 5.0, 0.0),
        scaled(&mut app, 10.0, -1.0),
    );
    let plain = ball(&mut app, Vec3::new(15.0, 0.0, 50.0), 3.0);
    let bad = scaled(&mut app, 20.0, f32::INFINITY);
    urto::step(app.world_mut(), 60).unwrap();
    let vz = |e| get::<Velocity>(&app, e).0.z;
    let g = 9.8;
    assert!((vz(half) + 0.5 * g).abs() < 1e-4, "{}", vz(half));
    assert!(vz(none).abs() < 1e-4 && (get::<Position>(&app, none).0.z - 50.0).abs() < 1e-4);
    assert!((vz(up) - g).abs() < 1e-4, "{}", vz(up));
    assert!((vz(plain) + g).abs() < 1e-4);
    assert!(app.world().get::<Quarantined>(bad).is_some());
}

#[test]
fn a_cone_stands_on_its_base_within_1_degree_and_one_on_its_apex_falls_onto_its_side() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    let (h, r) = (0.4, 0.3);
    let cone = |app: &mut App, at: Vec3, turn: f32| {
        let pose = (Position(at), Rotation(glam::Quat::from_rotation_x(turn)));
        let body = (Collider::cone(h, r), Velocity::default(), Density(500.0));
        app.world_mut().spawn((body, pose)).id()
    };
    let standing = cone(&mut app, Vec3::new(0.0, 0.0, h + 0.05), 0.0);
    // Upside down, a hair off its apex's balance.
    let tipping = cone(
        &mut app,
        Vec3::new(3.0, 0.0, h + 0.05),
        std::f32::consts::PI - 0.02,
    );
    urto::step(app.world_mut(), 180).unwrap();
    let up = |e| get::<Rotation>(&app, e).0 * Vec3::Z;
    let tilt = |e| up(e).angle_between(Vec3::Z).to_degrees();
    assert!(tilt(standing) < 1.0, "{}", tilt(standing));
    // Its base rests on the ground: the origin half the height above it.
    let z = get::<Position>(&app, standing).0.z;
    assert!((z - h).abs() < 0.01, "{z}");
    // It starts at 178.9°; lying on its side its axis is 90° + atan(r / 2h) = 110.6° from up.
    assert!((tilt(tipping) - 110.6).abs() < 5.0, "{}", tilt(tipping));
    let mass = get::<ComputedMass>(&app, standing).value();
    let expected = 500.0 * std::f32::consts::PI * r * r * 2.0 * h / 3.0;
    assert!((mass / expected - 1.0).abs() < 1e-5, "{mass} vs {expected}");
}

#[test]
fn a_body_spawned_mid_game_or_given_mass_while_asleep_or_without_the_plugin_weighs_right() {
    use bevy_app::PluginGroup;
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    urto::step(app.world_mut(), 5).unwrap();
    // Spawned after steps ran: its volume's mass at the next step.
    let late = common::ball(&mut app, Vec3::new(0.0, 0.0, 0.5));
    let heavy = ball(&mut app, Vec3::new(3.0, 0.0, 0.5), 2.0);
    urto::step(app.world_mut(), 120).unwrap();
    let ball_mass = DEFAULT_DENSITY * 4.0 / 3.0 * std::f32::consts::PI * 0.125;
    let mass = |app: &App, e| get::<ComputedMass>(app, e).value();
    assert!((mass(&app, late) / ball_mass - 1.0).abs() < 1e-5);
    // Asleep, it loses the mass it was given: it wakes and weighs its volume again.
    assert!(app.world().get::<Sleeping>(heavy).is_some(), "asleep first");
    app.world_mut().entity_mut(heavy).remove::<Mass>();
    urto::step(app.world_mut(), 1).unwrap();
    assert!(app.world().get::<Sleeping>(heavy).is_none(), "woken");
    assert!(
        (mass(&app, heavy) / ball_mass - 1.0).abs() < 1e-5,
        "{}",
        mass(&app, heavy)
    );

    // Without the mass-properties plugin, a kinematic body is kinematic still: gravity does
    // not pull it.
    let mut bare = App::new();
    let plugins = UrtoPlugins::default().build();
    bare.add_plugins(plugins.disable::<urto::plugins::MassPropertiesPlugin>());
    bare.insert_resource(Gravity::EARTH_Z_UP);
    let kinematic = bare
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::new(0.0, 0.0, 5.0),
            Velocity(Vec3::X),
        ))
        .insert(Mass::INFINITE)
        .id();
    urto::step(bare.world_mut(), 30).unwrap();
    assert_eq!(get::<Velocity>(&bare, kinematic).0, Vec3::X);
    assert_eq!(get::<Position>(&bare, kinematic).0.z, 5.0);
}

#[test]
fn translation_locks_hold_a_body_on_its_axes_bit_for_bit_and_removing_them_frees_it() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    // Locked along gravity's axis, with a game-written upward speed: it hangs where it is.
    let hanging = ball(&mut app, Vec3::new(0.0, 0.0, 5.0), 1.0);
    // A 2.5D body (gravity along −z, locked along y), kicked partly out of its plane.
    let planar = ball(&mut app, Vec3::new(5.0, 0.0, 0.5), 2.0);
    // A wall that slides along y only, struck head-on along x by a free ball.
    let wall = app
        .world_mut()
        .spawn((
            Collider::cuboid(0.5, 2.0, 2.0),
            Position(Vec3::new(12.0, 0.0, 2.0)),
            Velocity::default(),
            Mass(5.0),
            LockedAxes::new().lock_translation_x().lock_translation_z(),
        ))
        .id();
    let thrown = ball(&mut app, Vec3::new(10.0, 0.0, 2.0), 1.0);
    let world = app.world_mut();
    world.entity_mut(hanging).insert((
        LockedAxes::new().lock_translation_z(),
        Velocity(Vec3::new(0.0, 0.0, 3.0)),
    ));
    world.entity_mut(planar).insert((
        LockedAxes::new()
            .lock_translation_y()
            .lock_rotation_x()
            .lock_rotation_z(),
        Impulse::new(Vec3::new(4.0, 6.0, 0.0)),
    ));
    world.entity_mut(thrown).insert((
        Velocity(Vec3::new(6.0, 0.0, 0.0)),
        Restitution(1.0),
        GravityScale(0.0),
    ));
    world
        .entity_mut(wall)
        .insert((GravityScale(0.0), Restitution(1.0)));
    urto::step(app.world_mut(), 60).unwrap();
    let p = |app: &App, e| get::<Position>(app, e).0;
    let v = |app: &App, e| get::<Velocity>(app, e).0;
    assert_eq!(p(&app, hanging).z, 5.0, "the z-locked ball fell or rose");
    assert_eq!(v(&app, hanging), Vec3::ZERO);
    assert_eq!(p(&app, planar).y, 0.0, "the y-locked ball left its plane");
    // 4 N·s on 2 kg: 2 m/s along x, then rolling on the ground (friction slows the slide).
    assert!(p(&app, planar).x > 5.5 && v(&app, planar).y == 0.0);
    // Head-on against a body immovable along x: the ball bounces back at its own speed
    // (e = 1), the wall has not moved at all.
    assert_eq!(p(&app, wall), Vec3::new(12.0, 0.0, 2.0));
    assert!(
        (v(&app, thrown).x + 6.0).abs() < 0.06,
        "the ball came back at {}",
        v(&app, thrown)
    );
    // Unlocked, the hanging ball falls (it slept while hanging; the removal wakes it).
    assert!(app.world().get::<Sleeping>(hanging).is_some());
    app.world_mut().entity_mut(hanging).remove::<LockedAxes>();
    urto::step(app.world_mut(), 30).unwrap();
    assert!(p(&app, hanging).z < 4.0, "still at {}", p(&app, hanging));
}

#[test]
fn a_2d_stack_locked_to_the_xy_plane_rests_under_1_mm_per_s_and_sleeps_within_2_s() {
    // A 2D game's lock (translation along z, turning about x and y) with gravity along −y:
    // a contact normal in the plane got friction directions out of it, and per point the two
    // rows never settled: the top box slid at up to 3 cm/s and turned at 0.1 rad/s for ever
    // (a user-style probe; with gravity along −z and the lock along y it rested).
    let lock = LockedAxes::new()
        .lock_translation_z()
        .lock_rotation_x()
        .lock_rotation_y();
    let stack = |sleeping: bool| {
        let mut app = common::app();
        app.insert_resource(Gravity::new(Vec3::new(0.0, -9.81, 0.0)).unwrap());
        if !sleeping {
            app.insert_resource(SleepSettings {
                enabled: false,
                ..Default::default()
            });
        }
        let world = app.world_mut();
        world.spawn((Collider::half_space(Vec3::Y), Static));
        let boxes = [
            (Vec3::new(0.4, 0.3, 0.5), Vec3::new(0.0, 0.3, 0.0)),
            (Vec3::new(0.3, 0.2, 0.3), Vec3::new(0.2, 0.81, 0.0)),
        ]
        .map(|(h, at)| {
            let shape = Collider::cuboid(h.x, h.y, h.z);
            world
                .spawn((shape, Position(at), Velocity::default(), lock))
                .id()
        });
        (app, boxes)
    };
    let (mut app, boxes) = stack(false);
    urto::step(app.world_mut(), 480).unwrap();
    let (mut v, mut w) = (0.0f32, 0.0f32);
    for _ in 0..120 {
        urto::step(app.world_mut(), 1).unwrap();
        for e in boxes {
            v = v.max(get::<Velocity>(&app, e).0.length());
            w = w.max(get::<AngularVelocity>(&app, e).0.length());
        }
    }
    assert!(v < 1e-3 && w < 1e-3, "{v} m/s, {w} rad/s");
    let (mut app, boxes) = stack(true);
    urto::step(app.world_mut(), 120).unwrap();
    assert!(
        boxes
            .iter()
            .all(|&e| app.world().get::<Sleeping>(e).is_some())
    );
}

//! Bad input is reported and set aside; it never panics and never poisons a neighbour. And
//! valid but extreme input ([`scene_fuzz`]: random scenes of every shape, joint and setting at
//! the ends of their ranges) steps without a panic or a NaN.

#[path = "../common/mod.rs"]
mod common;
mod hierarchy;
mod removed_volume;
mod scene_fuzz;

use glam::{Quat, Vec3};
use urto::geometry::Shape;
use urto::prelude::*;

fn quarantined(app: &bevy_app::App, e: bevy_ecs::entity::Entity) -> bool {
    app.world().get::<Quarantined>(e).is_some()
}

#[test]
fn nan_and_infinite_state_is_quarantined_and_neighbours_stay_finite() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    let good = common::ball(&mut app, Vec3::new(0.0, 0.0, 0.6));
    let bad = [
        common::ball(&mut app, Vec3::new(f32::NAN, 0.0, 0.6)),
        app.world_mut()
            .spawn((
                Collider::sphere(0.5),
                Position::new(0.2, 0.0, 0.6),
                Velocity::new(f32::INFINITY, 0.0, 0.0),
            ))
            .id(),
        app.world_mut()
            .spawn((
                Collider::sphere(0.5),
                Position::new(0.1, 0.0, 0.6),
                Velocity::default(),
                Force(Vec3::NAN),
            ))
            .id(),
    ];
    urto::step(app.world_mut(), 30).unwrap();
    for e in bad {
        assert!(quarantined(&app, e));
    }
    assert!(!quarantined(&app, good));
    let p = app.world().get::<Position>(good).unwrap().0;
    assert!(
        p.is_finite() && p.z > 0.3,
        "the good ball was disturbed: {p}"
    );
}

/// A kinematic platform whose `KinematicTarget` is NaN, infinite, unreachable in a step
/// (1e38 m away) or turned by a quaternion of length 2 is quarantined; a ball resting on a
/// good platform beside them stays finite and seated within 1 mm.
#[test]
fn kinematic_targets_that_cannot_be_followed_are_quarantined() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let platform = |app: &mut bevy_app::App, x: f32, target: KinematicTarget| {
        let slab = Collider::cuboid(1.0, 1.0, 0.25);
        let at = Position::new(x, 0.0, -0.25);
        let kinematic = (Velocity::default(), Mass::INFINITE);
        app.world_mut().spawn((slab, at, kinematic, target)).id()
    };
    let good = platform(
        &mut app,
        0.0,
        KinematicTarget::new(Vec3::new(0.0, 0.0, -0.25)),
    );
    let ball = common::ball(&mut app, Vec3::new(0.0, 0.0, 0.5));
    let doubled = Quat::from_xyzw(0.0, 0.0, 0.0, 2.0);
    let bad = [
        KinematicTarget::new(Vec3::NAN),
        KinematicTarget::new(Vec3::splat(f32::INFINITY)),
        KinematicTarget::new(Vec3::splat(1e38)),
        KinematicTarget::new(Vec3::ZERO).with_rotation(doubled),
    ]
    .into_iter()
    .zip(1..)
    .map(|(target, i)| platform(&mut app, 5.0 * i as f32, target))
    .collect::<Vec<_>>();
    urto::step(app.world_mut(), 60).unwrap();
    for e in bad {
        assert!(quarantined(&app, e));
    }
    assert!(!quarantined(&app, good));
    let p = app.world().get::<Position>(ball).unwrap().0;
    assert!(p.distance(Vec3::new(0.0, 0.0, 0.5)) < 1e-3, "ball at {p}");
}

#[test]
fn zero_negative_subnormal_and_nan_masses_are_quarantined() {
    let mut app = common::app();
    // 1e-40 is subnormal: `1/m` overflows to infinity.
    let masses = [0.0, -1.0, 1e-40, f32::NAN];
    let bad: Vec<_> = masses
        .iter()
        .map(|&m| app.world_mut().spawn((Velocity::default(), Mass(m))).id())
        .collect();
    let infinite = app
        .world_mut()
        .spawn((Velocity::new(1.0, 0.0, 0.0), Mass::INFINITE))
        .id();
    urto::step(app.world_mut(), 1).unwrap();
    for (e, m) in bad.iter().zip(masses) {
        let q = app.world().get::<Quarantined>(*e).expect("quarantined");
        assert!(q.reason.contains("mass"), "mass {m}: {}", q.reason);
    }
    assert!(
        !quarantined(&app, infinite),
        "infinite mass is a kinematic body, not an error"
    );
}

#[test]
fn bad_shapes_and_rotations_are_quarantined() {
    let mut app = common::app();
    let e1 = app.world_mut().spawn(Collider::sphere(-1.0)).id();
    let e2 = app
        .world_mut()
        .spawn(Collider::cuboid(1.0, f32::NAN, 1.0))
        .id();
    let e3 = app.world_mut().spawn(Collider::half_space(Vec3::ZERO)).id();
    let e4 = app
        .world_mut()
        .spawn((
            Collider::sphere(1.0),
            Rotation(glam::Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)),
        ))
        .id();
    let e5 = app.world_mut().spawn(Collider::capsule(f32::NAN, 0.5)).id();
    let e6 = app.world_mut().spawn(Collider::capsule(0.5, -0.1)).id();
    let e7 = app.world_mut().spawn(Collider::capsule(3e6, 0.5)).id();
    let e8 = app
        .world_mut()
        .spawn(Collider::cylinder(f32::NAN, 0.5))
        .id();
    let e9 = app.world_mut().spawn(Collider::cylinder(0.5, -1.0)).id();
    let e9b = app.world_mut().spawn(Collider::cone(0.5, f32::NAN)).id();
    let e10 = app
        .world_mut()
        .spawn(Collider::ellipsoid(0.5, f32::INFINITY, 0.5))
        .id();
    let e11 = app
        .world_mut()
        .spawn(Collider::ellipsoid(0.5, -0.1, 0.5))
        .id();
    // A hull is checked when it is built: unusable points are an error, nothing spawns.
    assert!(Collider::convex_hull(&[Vec3::ZERO, Vec3::X, Vec3::Y]).is_err());
    assert!(Collider::convex_hull(&[Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::NAN]).is_err());
    assert!(Collider::convex_hull(&[Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::X + Vec3::Y]).is_err());
    assert!(Collider::convex_hull_from_file("no/such/hull.obj").is_err());
    // A readable mesh whose vertices are flat (one square) makes no hull: a hull error.
    let flat = std::env::temp_dir().join(format!("urto-flat-hull-{}.obj", std::process::id()));
    std::fs::write(
        &flat,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    let refused = Collider::convex_hull_from_file(&flat);
    let _ = std::fs::remove_file(&flat);
    assert!(matches!(
        refused,
        Err(urto::geometry::convex::HullFileError::Hull(_))
    ));
    // A good capsule next to the bad ones stays good.
    let good = app
        .world_mut()
        .spawn((Collider::capsule(0.5, 0.25), Velocity::default()))
        .id();
    urto::step(app.world_mut(), 1).unwrap();
    for e in [e1, e2, e3, e4, e5, e6, e7, e8, e9, e9b, e10, e11] {
        assert!(quarantined(&app, e));
    }
    assert!(!quarantined(&app, good));
}

#[test]
fn an_overflowing_kinematic_body_is_caught_and_a_dynamic_one_is_held_to_400_m_per_s() {
    let mut app = common::app();
    // A kinematic body keeps the speed the game gave it, and overflows.
    let huge = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Mass::INFINITE,
            Velocity::new(f32::MAX, 0.0, 0.0),
            Position::new(f32::MAX * 0.99, 0.0, 0.0),
        ))
        .id();
    // A dynamic one is held to the solver's speed bound.
    let fast = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Velocity::new(f32::MAX, -f32::MAX, 0.0),
            Position::new(0.0, 100.0, 0.0),
        ))
        .id();
    let neighbour = app
        .world_mut()
        .spawn((Collider::sphere(0.5), Velocity::default()))
        .id();
    urto::step(app.world_mut(), 3).unwrap();
    assert!(quarantined(&app, huge));
    assert_eq!(
        app.world().get::<Position>(neighbour).unwrap().0,
        Vec3::ZERO
    );
    let v = app.world().get::<Velocity>(fast).unwrap().0;
    let bound = SoftStepSettings::default().max_linear_speed;
    assert!(!quarantined(&app, fast));
    assert!((v.length() / bound - 1.0).abs() < 1e-5, "{v}");
    assert!((v.normalize() - Vec3::new(1.0, -1.0, 0.0).normalize()).length() < 1e-5);
}

#[test]
fn bad_settings_are_errors() {
    for dt in [0.0, -0.01, f32::NAN, f32::INFINITY, 10.0] {
        assert!(PhysicsTimestep::new(dt, 1).is_err(), "dt = {dt}");
    }
    assert!(PhysicsTimestep::new(0.01, 0).is_err());
    assert!(
        PhysicsTimestep::new(0.01, 1)
            .unwrap()
            .with_max_steps_per_frame(0)
            .is_err()
    );
    assert!(Gravity::new(Vec3::new(0.0, f32::NAN, 0.0)).is_err());
    let e = PhysicsTimestep::new(-1.0, 1).unwrap_err();
    assert!(e.to_string().contains("time step"), "{e}");
}

/// A step below a microsecond is refused: Bevy's fixed clock counts nanoseconds and panics on a
/// zero step. The smallest accepted step runs inside an `App` with Bevy's clock.
#[test]
fn a_step_below_1_microsecond_is_refused_and_the_smallest_accepted_one_runs_in_an_app() {
    assert!(PhysicsTimestep::new(1e-12, 1).is_err());
    assert!(PhysicsTimestep::new(0.9e-6, 1).is_err());
    let tiny = PhysicsTimestep::new(urto::settings::MIN_DT, 1).expect("1 µs is accepted");
    let mut app = bevy_app::App::new();
    app.add_plugins((bevy_time::TimePlugin, UrtoPlugins::with_timestep(tiny)));
    app.world_mut()
        .spawn((Collider::sphere(0.5), Velocity::new(1.0, 0.0, 0.0)));
    app.finish();
    app.cleanup();
    for _ in 0..3 {
        app.update();
    }
}

/// Iteration counts of `u32::MAX` run at most `MAX_ITERATIONS` sweeps: the step ends, and the
/// ball still rests on the ground.
#[test]
fn u32_max_solver_iterations_end_after_at_most_256_sweeps() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.insert_resource(ContactSettings {
        solver: urto::dynamics::response::SolverSettings {
            velocity_iterations: u32::MAX,
            position_iterations: u32::MAX,
            ..Default::default()
        },
        ..Default::default()
    });
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    let ball = common::ball(&mut app, Vec3::new(0.0, 0.0, 0.5));
    urto::step(app.world_mut(), 10).unwrap();
    let z = app.world().get::<Position>(ball).unwrap().0.z;
    assert!((z - 0.5).abs() < 0.01, "ball at {z}");
    assert_eq!(urto::dynamics::response::MAX_ITERATIONS, 256);
}

/// A NaN or negative speculative distance (each would silently read as no lookahead) and a
/// negative reach ratio are refused with the defaults back, and a dropped ball falls 2 m
/// within 1 s.
#[test]
fn unusable_speculative_margins_are_refused_with_the_defaults_and_a_dropped_ball_falls_2m_within_1s()
 {
    use urto::plugins::SpeculativeMargin;
    for bad in [
        SpeculativeMargin {
            distance: f32::NAN,
            ..Default::default()
        },
        SpeculativeMargin {
            distance: -0.01,
            ..Default::default()
        },
        SpeculativeMargin {
            reach_ratio: -1.0,
            ..Default::default()
        },
    ] {
        let (mut app, ball) = dropped_ball();
        app.insert_resource(bad);
        urto::step(app.world_mut(), 60).unwrap();
        assert_eq!(
            *app.world().resource::<SpeculativeMargin>(),
            SpeculativeMargin::default()
        );
        let z = app.world().get::<Position>(ball).unwrap().0.z;
        assert!(z < 8.0, "z = {z}");
    }
}

/// A ball dropped from 10 m above a bare world, after its first step (for the settings tests:
/// it must fall 2 m within 1 s whatever a refused setting would have done).
fn dropped_ball() -> (bevy_app::App, bevy_ecs::entity::Entity) {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let ball = common::ball(&mut app, Vec3::new(0.0, 0.0, 10.0));
    urto::step(app.world_mut(), 1).unwrap();
    (app, ball)
}

/// A sleep time of 0 would let every body count as still at once and sleep in mid-air: refused
/// with the defaults back, and a dropped ball falls 2 m within 1 s.
#[test]
fn a_zero_sleep_time_is_refused_and_a_dropped_ball_falls_2m_within_1s() {
    let (mut app, ball) = dropped_ball();
    app.world_mut().resource_mut::<SleepSettings>().time = 0.0;
    urto::step(app.world_mut(), 60).unwrap();
    assert_eq!(
        *app.world().resource::<SleepSettings>(),
        SleepSettings::default()
    );
    let z = app.world().get::<Position>(ball).unwrap().0.z;
    assert!(z < 8.0, "z = {z}");
}

/// Removes resource `R` after the scene settled, steps on, and returns the ball's height.
fn height_after_removing<R: bevy_ecs::resource::Resource>() -> f32 {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    app.world_mut().spawn((
        Collider::cuboid(5.0, 5.0, 0.5),
        Position::new(20.0, 0.0, 0.0),
        Static,
    ));
    let ball = common::ball(&mut app, Vec3::new(0.0, 0.0, 2.0));
    let on_slab = common::ball(&mut app, Vec3::new(20.0, 0.0, 2.0));
    urto::step(app.world_mut(), 10).unwrap();
    assert!(app.world_mut().remove_resource::<R>().is_some());
    urto::step(app.world_mut(), 110).unwrap();
    assert!(app.world().contains_resource::<R>(), "made again");
    let z = |e| app.world().get::<Position>(e).unwrap().0.z;
    z(ball).min(z(on_slab) - 0.5)
}

/// Removing any resource a stage runs on is input, not a crash: the resource is made again
/// (with a warning), and both balls end resting, on the ground and on a slab in the static
/// grid, within 2 cm (the broad-phase index, made again empty, re-indexes the scenery).
#[test]
fn removing_a_required_resource_between_steps_keeps_balls_resting_within_2cm() {
    let heights = [
        height_after_removing::<ContactSettings>(),
        height_after_removing::<SleepSettings>(),
        height_after_removing::<PhysicsTimestep>(),
        height_after_removing::<urto::settings::Integration>(),
        height_after_removing::<RotationSettings>(),
        height_after_removing::<urto::plugins::CcdSettings>(),
        height_after_removing::<urto::plugins::Contacts>(),
        height_after_removing::<urto::plugins::BroadPhasePairs>(),
        height_after_removing::<urto::plugins::BroadPhaseIndex>(),
        height_after_removing::<urto::plugins::GatheredForces>(),
        height_after_removing::<urto::plugins::SoftStepSolver>(),
        height_after_removing::<urto::plugins::SpeculativeMargin>(),
        height_after_removing::<PhysicsStats>(),
        height_after_removing::<SleepingIslands>(),
    ];
    for (i, z) in heights.into_iter().enumerate() {
        assert!((z - 0.5).abs() < 0.02, "resource {i}: height {z}");
    }
}

/// A ball, a neighbour touching it and a ground; returns `(app, ball, neighbour)`.
fn pair_on_ground() -> (
    bevy_app::App,
    bevy_ecs::entity::Entity,
    bevy_ecs::entity::Entity,
) {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    let mut ball = |x: f32| common::ball(&mut app, Vec3::new(x, 0.0, 0.5));
    let (a, b) = (ball(0.0), ball(0.9));
    (app, a, b)
}

/// Sizes are kept in a band: a sphere of radius `f32::MAX` (which turned its neighbour NaN) is
/// refused with a reason naming the bound, and the neighbour stays finite and on the ground.
#[test]
fn a_sphere_above_1000_km_is_quarantined_and_its_neighbour_stays_within_1cm_of_rest() {
    for radius in [f32::MAX, 2.0e6] {
        let (mut app, a, b) = pair_on_ground();
        app.world_mut()
            .entity_mut(a)
            .insert(Collider::sphere(radius));
        urto::step(app.world_mut(), 60).unwrap();
        let why = &app.world().get::<Quarantined>(a).expect("refused").reason;
        assert!(why.contains("largest supported"), "{why}");
        let p = app.world().get::<Position>(b).unwrap().0;
        assert!(p.is_finite() && (p.z - 0.5).abs() < 0.01, "{p}");
    }
    assert!(Shape::sphere(1.0e6).validate().is_ok());
}

/// A finite normal too long to square (1e20) still normalises, and the ground holds.
#[test]
fn a_half_space_normal_of_length_1e20_normalises_and_holds_a_ball_within_1cm() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::new(0.0, 0.0, 1.0e20)), Static));
    let ball = common::ball(&mut app, Vec3::new(0.0, 0.0, 1.0));
    urto::step(app.world_mut(), 120).unwrap();
    let z = app.world().get::<Position>(ball).unwrap().0.z;
    assert!((z - 0.5).abs() < 0.01, "z = {z}");
    assert!(
        Shape::half_space(Vec3::new(1e-30, 0.0, 0.0))
            .validate()
            .is_ok()
    );
    assert!(Shape::half_space(Vec3::ZERO).validate().is_err());
}

/// A spring of 1e12 N/m on a 1 kg ball (`k·w·h²` ≈ 2e7 at the solver's 1/240 s substep, where
/// an explicit step diverges above 4) flung the ball it touched to 1e21 m/s. The solver lowers
/// it to `k·w·h² = 1/4` (14,400 N/m) and its damping to `c·w·h = 1/2`: the ball then moves as
/// that spring allows (at most `ω·|x₀|` = 120 rad/s × 2.5 m = 300 m/s), ends within 25 cm of the
/// anchor, and the neighbour stays finite; a counter says one spring was lowered.
#[test]
fn a_1e12_spring_is_lowered_to_the_stable_bound_keeps_below_its_300_m_per_s_energy_bound() {
    let (mut app, a, b) = pair_on_ground();
    let anchor = Vec3::new(0.0, 0.0, 3.0);
    app.world_mut().entity_mut(a).insert(Spring {
        target: SpringTarget::Point(anchor),
        rest_length: 0.0,
        stiffness: 1.0e12,
        damping: 1.0e12,
    });
    let mut fastest = 0.0f32;
    for _ in 0..120 {
        urto::step(app.world_mut(), 1).unwrap();
        fastest = fastest.max(app.world().get::<Velocity>(a).unwrap().0.length());
    }
    assert!(fastest < 300.0, "fastest {fastest} m/s");
    let p = app.world().get::<Position>(a).unwrap().0;
    assert!(p.distance(anchor) < 0.25, "{p}");
    assert!(app.world().get::<Position>(b).unwrap().0.is_finite());
    let clamped = app
        .world()
        .resource::<PhysicsStats>()
        .counter("soft_step/springs_clamped");
    assert_eq!(clamped, Some(1.0));
}

/// Settings are public fields, so each is checked when it changes: a NaN sleep speed (every
/// comparison false: every body "still", asleep in mid-air), a negative default friction and a
/// NaN CCD ratio are refused with the defaults back, and a dropped ball falls 2 m within 1 s.
#[test]
fn unusable_settings_are_refused_with_the_defaults_and_a_dropped_ball_falls_2m_within_1s() {
    let (mut app, ball) = dropped_ball();
    app.world_mut().resource_mut::<SleepSettings>().speed = f32::NAN;
    app.world_mut()
        .resource_mut::<ContactSettings>()
        .default_friction = -1.0;
    app.world_mut()
        .resource_mut::<urto::plugins::CcdSettings>()
        .auto_speed_ratio = Some(f32::NAN);
    urto::step(app.world_mut(), 60).unwrap();
    assert_eq!(
        *app.world().resource::<SleepSettings>(),
        SleepSettings::default()
    );
    assert_eq!(
        *app.world().resource::<ContactSettings>(),
        ContactSettings::default()
    );
    assert_eq!(
        *app.world().resource::<urto::plugins::CcdSettings>(),
        urto::plugins::CcdSettings::default()
    );
    let z = app.world().get::<Position>(ball).unwrap().0.z;
    assert!(z < 8.0, "z = {z}");
}

/// A 10 g ball welded to two world points 3.7 m apart: the welds fight in every pass, and the
/// impulses they carry into the next step are held to the warm-start bound, which the
/// recording's counter `soft_step/bounded_joints` reports; the ball stays finite and under the
/// 400 m/s speed bound for 2 s.
#[test]
fn two_fighting_welds_are_held_by_the_warm_start_bound_and_the_counter_reports_it() {
    let mut app = common::app();
    let ball = app
        .world_mut()
        .spawn((
            Collider::sphere(0.02),
            Position::default(),
            Velocity::default(),
            Mass(0.01),
        ))
        .id();
    for (local, world) in [
        (Vec3::new(0.5, 0.0, 0.0), Vec3::new(-2.0, 0.0, 0.0)),
        (Vec3::new(0.0, -0.7, 0.3), Vec3::new(1.0, 2.0, 0.5)),
    ] {
        app.world_mut()
            .spawn(Joint::fixed(ball, JointEnd::World).with_anchors(local, world));
    }
    let mut steps_bounded = 0;
    for _ in 0..120 {
        urto::step(app.world_mut(), 1).unwrap();
        let v = app.world().get::<Velocity>(ball).unwrap().0;
        assert!(v.is_finite() && v.length() <= 400.0 * 1.001, "{v}");
        let bounded = app
            .world()
            .resource::<PhysicsStats>()
            .counter("soft_step/bounded_joints");
        steps_bounded += usize::from(bounded.is_some_and(|n| n > 0.0));
    }
    assert!(steps_bounded > 0, "the counter never reported the bound");
    assert!(app.world().get::<Quarantined>(ball).is_none());
}

//! Continuous collision between two moving bodies: head-on balls, bullets into free and sleeping
//! planks, a bullet's momentum handed to the box it hits, and no stop where the body's own
//! shape misses.

use super::common;
use bevy_app::App;
use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use urto::plugins::CcdSettings;
use urto::prelude::*;

fn weightless(substeps: u32) -> App {
    let mut app = common::app_with(1.0 / 60.0, substeps);
    app.insert_resource(Gravity::new(Vec3::ZERO).unwrap());
    app
}

fn without_ccd(app: &mut App) {
    app.insert_resource(CcdSettings {
        auto_speed_ratio: None,
        ..Default::default()
    });
}

fn at(app: &App, e: Entity) -> Vec3 {
    app.world().get::<Position>(e).unwrap().0
}

fn velocity(app: &App, e: Entity) -> Vec3 {
    app.world().get::<Velocity>(e).unwrap().0
}

/// 100 pairs of 5 cm balls flying at each other, the gap between them at the step they would
/// meet offset by up to a ball's size: which pairs end with the balls swapped.
fn head_on(speed: f32, substeps: u32, ccd: bool) -> (App, Vec<(Entity, Entity)>) {
    let mut app = weightless(substeps);
    if !ccd {
        without_ccd(&mut app);
    }
    let pairs = (0..100)
        .map(|i| {
            let y = i as f32;
            let ball = |x: f32, v: f32| {
                (
                    Collider::sphere(0.05),
                    Position::new(x, y, 0.0),
                    Velocity::new(v, 0.0, 0.0),
                )
            };
            let offset = 0.37 * i as f32 / 100.0;
            let a = app.world_mut().spawn(ball(0.0, speed)).id();
            let b = app.world_mut().spawn(ball(10.0 + offset, -speed)).id();
            (a, b)
        })
        .collect();
    let steps = (10.0 / speed * 60.0) as u32 + 3;
    urto::step(app.world_mut(), steps).unwrap();
    (app, pairs)
}

/// Balls of 10 cm closing at 20–800 m/s never pass through each other with the default
/// automatic CCD (one substep or four) and bounce apart, mirror images within 1 mm; without
/// CCD most pairs pass (the speculative contacts look ahead only as far as the balls' size).
#[test]
fn head_on_balls_at_10_to_400_m_s_never_pass_through_each_other_and_bounce_mirrored_within_1_mm() {
    for speed in [10.0, 60.0, 200.0, 400.0] {
        for substeps in [1, 4] {
            let (app, pairs) = head_on(speed, substeps, true);
            for &(a, b) in &pairs {
                let (pa, pb) = (at(&app, a), at(&app, b));
                assert!(pa.x < pb.x, "{speed} m/s, {substeps} substeps: {pa} {pb}");
                assert!(velocity(&app, a).x < 0.0 && velocity(&app, b).x > 0.0);
                // Pair i starts mirrored about x = 5 + offset / 2 (offset 0.37 i / 100), and
                // stays so.
                let mid = (pa.x + pb.x) / 2.0;
                let start_mid = 5.0 + 0.37 * pb.y / 100.0 / 2.0;
                assert!(
                    (mid - start_mid).abs() < 1e-3,
                    "{speed} m/s: mid {mid} vs {start_mid}"
                );
            }
        }
        let (app, pairs) = head_on(speed, 1, false);
        let passed = pairs
            .iter()
            .filter(|(a, b)| at(&app, *a).x > at(&app, *b).x)
            .count();
        assert!(passed > 10, "{speed} m/s without CCD: {passed} passed");
    }
}

/// Bullets of 10 cm at 10–400 m/s, up to 60° off the normal, against a free plank 1 cm thick
/// (a tonne, so that it barely moves), awake or asleep: none crosses the plank inside its face
/// in a step; without CCD most do.
#[test]
fn no_bullet_crosses_a_free_or_sleeping_1_cm_plank_in_a_step_and_most_do_without_ccd() {
    let run = |ccd: bool, asleep: bool| {
        let mut app = weightless(1);
        if !ccd {
            without_ccd(&mut app);
        }
        let plank = app
            .world_mut()
            .spawn((
                Collider::cuboid(0.005, 10.0, 10.0),
                Position::new(5.0, 0.0, 0.0),
                Velocity::default(),
                Mass(1000.0),
            ))
            .id();
        if asleep {
            // Still for longer than the sleep time: it falls asleep before the bullets come.
            urto::step(app.world_mut(), 60).unwrap();
            assert!(app.world().get::<Sleeping>(plank).is_some());
        }
        let mut rng = common::rng::Rng::new(17);
        let bullets: Vec<Entity> = (0..200)
            .map(|_| {
                let speed = 10f32.powf(rng.range(1.0, 2.6));
                let dir = Quat::from_rotation_z(rng.range(-1.0, 1.0))
                    * Quat::from_rotation_y(rng.range(-0.5, 0.5))
                    * Vec3::X;
                let from = Vec3::new(0.0, rng.range(-2.0, 2.0), rng.range(-2.0, 2.0));
                let bullet = (
                    Collider::sphere(0.05),
                    Position(from),
                    Velocity(dir * speed),
                );
                app.world_mut().spawn(bullet).id()
            })
            .collect();
        let mut crossed = 0;
        for _ in 0..30 {
            let x = at(&app, plank).x;
            let before: Vec<Vec3> = bullets.iter().map(|&b| at(&app, b)).collect();
            urto::step(app.world_mut(), 1).unwrap();
            for (&b, p) in bullets.iter().zip(&before) {
                let q = at(&app, b);
                if p.x < x - 0.005 && q.x > x + 0.005 {
                    let c = p.lerp(q, (x - p.x) / (q.x - p.x));
                    crossed += usize::from(c.y.abs() < 10.0 && c.z.abs() < 10.0);
                }
            }
        }
        crossed
    };
    for asleep in [false, true] {
        assert_eq!(run(true, asleep), 0, "asleep: {asleep}");
        assert!(run(false, asleep) > 100, "asleep: {asleep}");
    }
}

/// A 1 kg ball at 100 m/s into a free 10 kg box at rest (no restitution, no friction, no
/// gravity): after the hit the two share the momentum, `m v / (m + M)` each within 1 %, and
/// the ball is never past the box's far face.
#[test]
fn a_ball_at_100_m_s_into_a_free_box_hands_it_its_momentum_within_1_percent() {
    let mut app = weightless(1);
    let ball = app
        .world_mut()
        .spawn((
            Collider::sphere(0.05),
            Position::new(0.0, 0.0, 0.0),
            Velocity::new(100.0, 0.0, 0.0),
            Mass(1.0),
            Restitution(0.0),
            Friction(0.0),
        ))
        .id();
    let block = app
        .world_mut()
        .spawn((
            Collider::cuboid(0.25, 0.25, 0.25),
            Position::new(5.0, 0.0, 0.0),
            Velocity::default(),
            Mass(10.0),
            Restitution(0.0),
            Friction(0.0),
        ))
        .id();
    for _ in 0..20 {
        urto::step(app.world_mut(), 1).unwrap();
        assert!(at(&app, ball).x < at(&app, block).x + 0.25);
    }
    let shared = 100.0 / 11.0;
    for e in [ball, block] {
        let v = velocity(&app, e);
        assert!((v.x - shared).abs() < 0.01 * shared, "{v}");
    }
}

/// A fast capsule lying along its flight, passing 10 cm beside a moving box: its bounding
/// sphere (1.1 m) meets the box, the capsule does not, and it flies on undisturbed (within
/// 1e-4 m of free flight); a sensor and a box on a layer it ignores stop nothing either.
#[test]
fn a_capsule_passing_beside_a_moving_box_a_sensor_or_an_ignored_layer_flies_on_within_1e_4_m() {
    let mut app = weightless(1);
    let capsule = app
        .world_mut()
        .spawn((
            Collider::capsule(1.0, 0.1),
            Position::new(0.0, 0.0, 0.0),
            Rotation(Quat::from_rotation_y(std::f32::consts::FRAC_PI_2)),
            Velocity::new(120.0, 0.0, 0.0),
        ))
        .id();
    let moving_box = (
        Collider::cuboid(0.2, 0.2, 0.2),
        Position::new(5.0, 0.4, 0.0),
        Velocity::new(0.0, -1.0, 0.0),
    );
    app.world_mut().spawn(moving_box);
    app.world_mut().spawn((
        Collider::cuboid(0.2, 0.2, 0.2),
        Position::new(9.0, 0.0, 0.0),
        Velocity::default(),
        Sensor,
    ));
    app.world_mut().spawn((
        Collider::cuboid(0.2, 0.2, 0.2),
        Position::new(13.0, 0.0, 0.0),
        Velocity::default(),
        CollisionLayers::new(LayerMask(2), LayerMask(2)),
    ));
    urto::step(app.world_mut(), 9).unwrap();
    let expected = 120.0 * 9.0 / 60.0;
    assert!(
        (at(&app, capsule) - Vec3::X * expected).length() < 1e-4,
        "{}",
        at(&app, capsule)
    );
    assert_eq!(velocity(&app, capsule), Vec3::new(120.0, 0.0, 0.0));
}

/// An impulse of 1e30 N·s sends a ball at a row of balls (and at one asleep): it goes off at
/// the speed bound and never through the next ball, and every state stays finite.
#[test]
fn a_ball_kicked_by_1e30_n_s_never_passes_through_the_ball_beside_it_and_nothing_turns_nan() {
    let mut app = weightless(4);
    let ball = |x: f32| {
        (
            Collider::sphere(0.5),
            Position::new(x, 0.0, 0.0),
            Velocity::default(),
        )
    };
    let kicked = app.world_mut().spawn(ball(0.0)).id();
    let row: Vec<Entity> = (1..6)
        .map(|k| app.world_mut().spawn(ball(k as f32 * 1.2)).id())
        .collect();
    urto::step(app.world_mut(), 60).unwrap();
    assert!(
        app.world().get::<Sleeping>(row[0]).is_some(),
        "the row sleeps"
    );
    app.world_mut()
        .entity_mut(kicked)
        .insert(Impulse::new(Vec3::X * 1e30));
    for _ in 0..30 {
        urto::step(app.world_mut(), 1).unwrap();
        assert!(
            at(&app, kicked).x < at(&app, row[0]).x,
            "{}",
            at(&app, kicked)
        );
    }
    for e in std::iter::once(kicked).chain(row) {
        assert!(at(&app, e).is_finite() && velocity(&app, e).is_finite());
    }
}

/// A kinematic paddle at 200 m/s (3.3 m a step, more than its size) follows the game's velocity
/// exactly, through a static wall and a free ball in its way: the sweeps never stop or bounce
/// a kinematic body (its velocity was reflected off the wall before), and the ball is hit.
#[test]
fn a_kinematic_paddle_at_200_m_s_keeps_its_velocity_through_a_wall_and_still_hits_a_ball() {
    let mut app = weightless(1);
    let paddle = app
        .world_mut()
        .spawn((
            Collider::cuboid(0.05, 1.0, 1.0),
            Position::new(0.0, 0.0, 0.0),
            Velocity::new(200.0, 0.0, 0.0),
            Mass::INFINITE,
        ))
        .id();
    let wall = (
        Collider::cuboid(0.05, 1.0, 1.0),
        Position::new(5.0, 0.0, 0.5),
        Static,
    );
    app.world_mut().spawn(wall);
    let ball = (
        Collider::sphere(0.1),
        Position::new(10.5, 0.0, 0.0),
        Velocity::default(),
    );
    let ball = app.world_mut().spawn(ball).id();
    for step in 1..=8 {
        urto::step(app.world_mut(), 1).unwrap();
        let expected = 200.0 * step as f32 / 60.0;
        assert!(
            (at(&app, paddle).x - expected).abs() < 1e-4,
            "{}",
            at(&app, paddle)
        );
        assert_eq!(velocity(&app, paddle), Vec3::new(200.0, 0.0, 0.0));
    }
    assert!(velocity(&app, ball).x > 200.0, "{}", velocity(&app, ball));
    assert!(at(&app, ball).x > at(&app, paddle).x);
}

/// Balls spawned on one point, flying off at 100 m/s in every direction (100 or 300 of them):
/// they spread as they do without continuous collision (the nearest one ends at least half as
/// far out). Stopping a body already deep inside another kept such a heap on its point for
/// good, at a second a step for 1,000 balls.
#[test]
fn balls_spawned_on_one_point_fly_apart_at_least_half_as_far_as_without_ccd() {
    let nearest = |n: usize, ccd: bool| {
        let mut app = weightless(4);
        if !ccd {
            without_ccd(&mut app);
        }
        let mut rng = common::rng::Rng::new(5);
        let balls: Vec<Entity> = (0..n)
            .map(|_| {
                let v = Vec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                );
                let v = Velocity(v.normalize_or(Vec3::X) * 100.0);
                let ball = (Collider::sphere(0.05), Position(Vec3::ZERO), v);
                app.world_mut().spawn(ball).id()
            })
            .collect();
        urto::step(app.world_mut(), 10).unwrap();
        balls
            .iter()
            .map(|&b| at(&app, b).length())
            .fold(f32::MAX, f32::min)
    };
    for n in [100, 300] {
        let (with, without) = (nearest(n, true), nearest(n, false));
        println!("{n} balls: nearest {with} m out with CCD, {without} without");
        assert!(
            with >= 0.5 * without,
            "{n} balls: {with} m against {without}"
        );
    }
}

/// A ball of radius `r` at `speed` along x into an equal ball at rest, both of restitution `e`
/// and no friction, the gap between them offset by `phase` of a step's travel: the two
/// velocities along x and the two centres after 0.5 s.
fn into_a_resting_ball(r: f32, speed: f32, e: f32, phase: f32) -> (f32, f32, f32, f32) {
    let mut app = common::app();
    app.insert_resource(Gravity::new(Vec3::ZERO).unwrap());
    let ball = |x: f32, v: f32| {
        (
            Collider::sphere(r),
            Position::new(x, 0.0, 0.0),
            Velocity::new(v, 0.0, 0.0),
            Restitution(e),
            Friction(0.0),
        )
    };
    let gap = (1.37 + phase) * speed / 60.0 + 0.3;
    let cue = app.world_mut().spawn(ball(0.0, speed)).id();
    let struck = app.world_mut().spawn(ball(2.0 * r + gap, 0.0)).id();
    urto::step(app.world_mut(), 30).unwrap();
    let (c, s) = (at(&app, cue).x, at(&app, struck).x);
    (velocity(&app, cue).x, velocity(&app, struck).x, c, s)
}

/// Balls of 2.5 cm and 10 cm, and pool balls (5.7 cm, e = 0.95), at 12–400 m/s into an equal
/// ball at rest hand it their speed as Newton's law of restitution says (`(1 − e) v / 2` and
/// `(1 + e) v / 2`) within 1 % of `v`, and the struck ball stays ahead. The sweep of a fast
/// ball against the ball it struck took that ball's motion in the step from its final
/// velocity, not the solve's (it had moved at half the speed the bounce then gave it): it was
/// put behind the cue ball, which passed through it, and the two leapfrogged each step.
#[test]
fn a_ball_at_12_to_400_m_s_into_an_equal_resting_one_hands_on_its_speed_within_1_percent() {
    for (r, e) in [(0.025, 1.0), (0.1, 1.0), (0.0286, 0.95)] {
        for speed in [12.0, 16.0, 40.0, 120.0, 400.0] {
            for phase in [0.0, 0.3, 0.7] {
                let (vc, vs, c, s) = into_a_resting_ball(r, speed, e, phase);
                let case = format!("r {r}, e {e}, {speed} m/s, phase {phase}");
                let (want_c, want_s) = ((1.0 - e) * speed / 2.0, (1.0 + e) * speed / 2.0);
                assert!((vc - want_c).abs() < 0.01 * speed, "{case}: cue at {vc}");
                assert!((vs - want_s).abs() < 0.01 * speed, "{case}: struck at {vs}");
                assert!(s - c > 2.0 * r - 1e-3, "{case}: cue at {c}, struck at {s}");
            }
        }
    }
}

//! Continuous collision through the plugin: fast balls never pass a 1 cm wall, while resting
//! and sliding bodies are left to the contact solver; fast bodies never pass through moving
//! ones ([`movers`]).

#[path = "../common/mod.rs"]
mod common;
mod movers;

use bevy_app::App;
use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;
use common::rng::Rng;
use glam::{Quat, Vec3};
use urto::geometry::TriMesh;
use urto::plugins::CcdSettings;
use urto::prelude::*;

const WALL_HALF_THICKNESS: f32 = 0.005;

/// A wall 1 cm thick, 20 m × 20 m, across the x axis at x = 5: a box or a mesh of a box.
fn wall(app: &mut App, as_mesh: bool) {
    let half = Vec3::new(WALL_HALF_THICKNESS, 10.0, 10.0);
    let collider = if as_mesh {
        Collider::trimesh(TriMesh::cuboid(half).unwrap()).unwrap()
    } else {
        Collider::cuboid(half.x, half.y, half.z)
    };
    app.world_mut().spawn((
        collider,
        Position::new(5.0, 0.0, 0.0),
        Static,
        Restitution(0.5),
    ));
}

/// `n` balls of radius 5 cm from x = 0 towards the wall at 10–1000 m/s, up to 60° off its normal.
fn bullets(app: &mut App, n: usize, marked: bool, rng: &mut Rng) -> Vec<Entity> {
    (0..n)
        .map(|_| {
            let speed = 10f32.powf(rng.range(1.0, 3.0));
            let dir = Quat::from_rotation_z(rng.range(-1.0, 1.0))
                * Quat::from_rotation_y(rng.range(-0.5, 0.5))
                * Vec3::X;
            let at = Vec3::new(0.0, rng.range(-2.0, 2.0), rng.range(-2.0, 2.0));
            let mut e = app.world_mut().spawn((
                Collider::sphere(0.05),
                Position(at),
                Velocity(dir * speed),
                Friction(0.0),
            ));
            if marked {
                e.insert(Ccd);
            }
            e.id()
        })
        .collect()
}

fn passed(app: &App, balls: &[Entity]) -> usize {
    balls
        .iter()
        .filter(|b| app.world().get::<Position>(**b).unwrap().0.x > 5.0)
        .count()
}

/// Steps `steps` times and counts the balls whose motion in some step crossed the wall's plane
/// inside its 20 m × 20 m face: tunnelled through it. (A ball knocked sideways by another one
/// may fly round the wall's edge; that is no tunnelling.)
fn tunnelled(app: &mut App, balls: &[Entity], steps: u32) -> usize {
    let at = |app: &App| -> Vec<Vec3> {
        balls
            .iter()
            .map(|b| app.world().get::<Position>(*b).unwrap().0)
            .collect()
    };
    let mut through = vec![false; balls.len()];
    let mut before = at(app);
    for _ in 0..steps {
        urto::step(app.world_mut(), 1).unwrap();
        let after = at(app);
        for (i, (p, q)) in before.iter().zip(&after).enumerate() {
            if p.x < 5.0 && q.x > 5.0 {
                let crossing = p.lerp(*q, (5.0 - p.x) / (q.x - p.x));
                through[i] |= crossing.y.abs() < 10.0 && crossing.z.abs() < 10.0;
            }
        }
        before = after;
    }
    through.iter().filter(|t| **t).count()
}

/// With CCD (marked bodies, automatic sweeping off), none of 300 bullets at up to 1000 m/s
/// passes through a 1 cm box wall or a 1 cm mesh wall; without it most do (the speculative
/// margin covers a body's motion up to its own size only).
#[test]
fn no_bullet_passes_a_1cm_wall_with_ccd_and_most_do_without() {
    for as_mesh in [false, true] {
        let run = |marked: bool| {
            let mut app = common::legacy_app();
            app.insert_resource(CcdSettings {
                auto_speed_ratio: None,
                ..Default::default()
            });
            wall(&mut app, as_mesh);
            let balls = bullets(&mut app, 300, marked, &mut Rng::new(17));
            tunnelled(&mut app, &balls, 30)
        };
        assert_eq!(run(true), 0, "mesh wall: {as_mesh}");
        assert!(
            run(false) > 200,
            "without CCD the wall is porous (mesh: {as_mesh})"
        );
    }
}

/// Automatic CCD (the default) catches fast bodies that are not marked.
#[test]
fn automatic_ccd_catches_unmarked_fast_bodies() {
    let mut app = common::app();
    wall(&mut app, false);
    let balls = bullets(&mut app, 100, false, &mut Rng::new(4));
    assert_eq!(tunnelled(&mut app, &balls, 30), 0);
    assert!(app.world().resource::<PhysicsStats>().runs("ccd") > 0);
}

/// An impact found only by the sweep is reported as a collision.
#[test]
fn a_swept_impact_starts_a_collision() {
    let mut app = common::app();
    wall(&mut app, false);
    app.world_mut().spawn((
        Collider::sphere(0.05),
        Position::new(4.0, 0.0, 0.0),
        Velocity::new(300.0, 0.0, 0.0),
        Ccd,
    ));
    let mut cursor = app
        .world()
        .resource::<Messages<CollisionStarted>>()
        .get_cursor();
    urto::step(app.world_mut(), 1).unwrap();
    let started = cursor
        .read(app.world().resource::<Messages<CollisionStarted>>())
        .count();
    assert_eq!(started, 1);
}

/// A marked ball already touching the 1 cm wall (1 mm gap, touching, 1 mm into it) and moving
/// into it at 10 or 30 m/s is stopped: the sweep takes a contact present at its start when the
/// motion goes into it, instead of leaving it to the solver, which sees only the substep's end.
#[test]
fn a_ball_touching_the_wall_and_moving_into_it_does_not_pass() {
    for gap in [0.001, 0.0, -0.001] {
        for speed in [10.0, 30.0] {
            let mut app = common::app();
            app.insert_resource(CcdSettings {
                auto_speed_ratio: None,
                ..Default::default()
            });
            wall(&mut app, false);
            let x = 5.0 - WALL_HALF_THICKNESS - 0.05 - gap;
            let ball = app
                .world_mut()
                .spawn((
                    Collider::sphere(0.05),
                    Position::new(x, 0.0, 0.0),
                    Velocity::new(speed, 0.0, 0.0),
                    Ccd,
                ))
                .id();
            urto::step(app.world_mut(), 3).unwrap();
            assert_eq!(passed(&app, &[ball]), 0, "gap {gap} m at {speed} m/s");
            let v = app.world().get::<Velocity>(ball).unwrap().0;
            assert!(v.x < 0.0, "bounced back: {v}");
        }
    }
}

/// A marked ball resting on the ground stays at rest, and one sliding along it keeps sliding:
/// contacts present at the start of a motion belong to the solver, not to the sweep.
#[test]
fn resting_and_sliding_marked_bodies_are_not_stopped_by_their_support() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static, Friction(0.0)));
    let resting = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::new(0.0, 0.0, 0.5),
            Velocity::default(),
            Ccd,
        ))
        .id();
    let sliding = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::new(0.0, 5.0, 0.5),
            Velocity::new(3.0, 0.0, 0.0),
            Ccd,
            Friction(0.0),
        ))
        .id();
    urto::step(app.world_mut(), 120).unwrap();
    let p = |e: Entity| app.world().get::<Position>(e).unwrap().0;
    assert!(
        (p(resting) - Vec3::new(0.0, 0.0, 0.5)).length() < 0.005,
        "{}",
        p(resting)
    );
    assert!((p(sliding).x - 6.0).abs() < 0.01, "slid to {}", p(sliding));
}

/// The centre of mass of `e` in the world.
fn center_of_mass(app: &App, e: Entity) -> Vec3 {
    let world = app.world();
    let (p, r) = (
        world.get::<Position>(e).unwrap().0,
        world.get::<Rotation>(e).unwrap().0,
    );
    p + r * world.get::<Inertia>(e).unwrap().local_center_of_mass
}

/// The fastest the centre of mass of `e` can move: its speed with all its spin energy turned
/// into speed, `√(v² + ω·Iω/m)` (a cone that really touches the wall, its own shape and not
/// its bounding sphere, turns spin into speed there).
fn speed_bound(app: &App, e: Entity) -> f32 {
    let world = app.world();
    let v = world.get::<Velocity>(e).unwrap().0;
    let w = world.get::<AngularVelocity>(e).unwrap().0;
    let r = world.get::<Rotation>(e).unwrap().0;
    let inertia = world.get::<Inertia>(e).unwrap();
    let local = (r * inertia.frame).inverse() * w;
    let spin_energy = (inertia.principal * local * local).element_sum();
    let m = world.get::<ComputedMass>(e).unwrap().value();
    (v.length_squared() + spin_energy / m).sqrt()
}

#[test]
fn spinning_cones_off_their_centre_bounce_off_the_wall_their_centre_moving_at_most_speed_dt_1e_3() {
    // A cone's centre of mass is a quarter of its height above the base, half a metre off its
    // origin here; spun fast and thrown at the wall, the sweep follows the centre of mass.
    let mut app = common::app();
    wall(&mut app, false);
    let mut rng = Rng::new(7);
    // 2.5 m apart: they never meet each other, only the wall.
    let cones: Vec<Entity> = (0..8)
        .map(|k| {
            let speed = rng.range(100.0, 300.0);
            let spin = Vec3::new(rng.range(-30.0, 30.0), rng.range(-30.0, 30.0), 40.0);
            let body = (Collider::cone(1.0, 0.4), Velocity(Vec3::X * speed), Ccd);
            let at = Position::new(0.0, k as f32 * 2.5 - 9.0, 0.0);
            app.world_mut()
                .spawn((body, at, AngularVelocity(spin)))
                .id()
        })
        .collect();
    urto::step(app.world_mut(), 1).unwrap();
    for _ in 0..30 {
        let before: Vec<(Vec3, f32)> = cones
            .iter()
            .map(|&c| (center_of_mass(&app, c), speed_bound(&app, c)))
            .collect();
        urto::step(app.world_mut(), 1).unwrap();
        for (&c, (from, speed)) in cones.iter().zip(before) {
            let moved = center_of_mass(&app, c).distance(from);
            let now = center_of_mass(&app, c);
            let v = app.world().get::<Velocity>(c).unwrap().0;
            assert!(
                moved <= speed / 60.0 * 1.001 + 1e-4,
                "{c}: {moved} m at {speed} m/s; from {from} to {now}, v {v}"
            );
        }
    }
    for &c in &cones {
        assert!(center_of_mass(&app, c).x < 5.0, "{c} passed the wall");
    }
}

/// A 10 cm wall whose face is at x = 9.95 and, flying at it at 120 m/s (2 m a step),
/// turned by `rotation` and spinning at `spin` rad/s about y, a body of `collider`.
fn broadside(collider: Collider, rotation: Quat, spin: f32) -> (App, Entity) {
    let mut app = common::app();
    app.world_mut().spawn((
        Collider::cuboid(0.05, 5.0, 5.0),
        Position(Vec3::new(10.0, 0.0, 0.0)),
        Static,
        Restitution(0.0),
    ));
    let body = app
        .world_mut()
        .spawn((
            collider,
            Position(Vec3::ZERO),
            Rotation(rotation),
            Velocity(Vec3::new(120.0, 0.0, 0.0)),
            AngularVelocity(Vec3::new(0.0, spin, 0.0)),
            Restitution(0.0),
            Ccd,
        ))
        .id();
    (app, body)
}

/// [`broadside`] for a compound's root: a 0.2 m thick box, 0.6 m long along y.
fn broadside_root(spin: f32) -> (App, Entity) {
    broadside(Collider::cuboid(0.1, 0.3, 0.1), Quat::IDENTITY, spin)
}

/// The farthest the body's x gets in 8 steps.
fn farthest_x(app: &mut App, body: Entity) -> f32 {
    let mut farthest = f32::MIN;
    for _ in 0..8 {
        urto::step(app.world_mut(), 1).unwrap();
        farthest = farthest.max(app.world().get::<Position>(body).unwrap().0.x);
    }
    farthest
}

#[test]
fn a_capsule_box_or_cylinder_flying_broadside_stops_at_the_wall_within_1_mm_not_its_sphere() {
    // A 2.2 m capsule 0.2 m thick, lying across its motion at 120 m/s (2 m a step) towards a
    // 10 cm wall whose face is at x = 9.95: it must meet the wall at x = 9.85. Its bounding
    // sphere (radius 1.1) met it at 8.85; the sweep used to stop (or bounce) it there. No
    // bounce here: the farthest it gets is where it met the wall.
    for (shape, touch) in [
        (Collider::capsule(1.0, 0.1), 9.85),
        (Collider::cuboid(0.1, 1.0, 0.1), 9.85),
        (Collider::cylinder(1.0, 0.1), 9.85),
    ] {
        // The capsule's and cylinder's axis (z) turned to lie along y.
        let lying = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
        let (mut app, body) = broadside(shape.clone(), lying, 0.0);
        let farthest = farthest_x(&mut app, body);
        assert!(
            farthest <= touch + 1e-3 && farthest > touch - 1e-3,
            "{shape:?} got to {farthest}"
        );
    }
}

#[test]
fn a_compound_of_a_box_a_ball_and_a_cylinder_flying_broadside_stops_at_the_wall_within_1_mm() {
    // A 2 m compound, every part 0.2 m thick along its motion: a box at its root, a ball and an
    // upright cylinder (axis along y after the turn) on children at y = ±0.9, a grandchild box
    // at y = -0.6 under the cylinder's child. It must meet the wall at x = 9.85; the sphere
    // holding all of it (radius about 1) met it a metre short. Spun about its long axis at
    // 3 rad/s, the boxes reach up to 0.1·√2 ahead of it: it meets the wall between x = 9.80
    // and 9.85 (where its end orientation, kept at the impact, would put a corner inside the
    // wall, it stops where that orientation first touches, not at its sphere).
    for (spin, nearest) in [(0.0, 9.85 - 1e-3), (3.0, 9.80)] {
        let (mut app, body) = broadside_root(spin);
        let world = app.world_mut();
        world.spawn((
            Collider::sphere(0.1),
            Position(Vec3::new(0.0, 0.9, 0.0)),
            ChildOf(body),
        ));
        let arm = world
            .spawn((
                Collider::cylinder(0.1, 0.1),
                Position(Vec3::new(0.0, -0.9, 0.0)),
                Rotation(Quat::from_rotation_x(std::f32::consts::FRAC_PI_2)),
                ChildOf(body),
            ))
            .id();
        // The arm is turned a quarter about x (its local z along the body's -y): the grandchild
        // at its local z = -0.3 sits at the body's y = -0.6.
        world.spawn((
            Collider::cuboid(0.1, 0.1, 0.1),
            Position(Vec3::new(0.0, 0.0, -0.3)),
            ChildOf(arm),
        ));
        let farthest = farthest_x(&mut app, body);
        assert!(
            farthest <= 9.85 + 1e-3 && farthest > nearest,
            "spin {spin}: got to {farthest}"
        );
    }
}

/// How far (the root's x) the compound of [`broadside_root`] with `child` gets.
fn compound_reach(child: impl Bundle) -> f32 {
    let (mut app, body) = broadside_root(0.0);
    app.world_mut().spawn((child, ChildOf(body)));
    farthest_x(&mut app, body)
}

#[test]
fn a_compound_with_a_mesh_part_stops_at_its_sphere_and_a_sensor_or_ghost_part_stops_nothing() {
    // A mesh part has no convex gap to advance on: the body stops where its sphere (radius
    // about 1) met the wall, a metre short of 9.85, early as before. A sensor ball reaching
    // 0.4 m ahead of the body is no part of its shape: it touches first, and the body still
    // gets to 9.85.
    let mesh = Collider::trimesh(TriMesh::cuboid(Vec3::splat(0.1)).unwrap()).unwrap();
    let with_mesh = compound_reach((mesh, Position(Vec3::new(0.0, 0.9, 0.0))));
    assert!(with_mesh < 9.0, "with a mesh part it got to {with_mesh}");
    let sensor = (
        Collider::sphere(0.3),
        Position(Vec3::new(0.2, 0.9, 0.0)),
        Sensor,
    );
    let with_sensor = compound_reach(sensor);
    assert!(
        with_sensor <= 9.85 + 1e-3 && with_sensor > 9.85 - 1e-3,
        "with a sensor part it got to {with_sensor}"
    );
    // A part 0.3 m ahead in layers the wall does not interact with passes it, as the narrow
    // phase would let it: the body stops where its root meets the wall, not 0.3 m short.
    let ghost = (
        Collider::cuboid(0.1, 0.1, 0.1),
        Position(Vec3::new(0.3, 0.9, 0.0)),
        CollisionLayers::new(LayerMask(1 << 2), !LayerMask(1)),
    );
    let with_ghost = compound_reach(ghost);
    assert!(
        with_ghost <= 9.85 + 1e-3 && with_ghost > 9.85 - 1e-3,
        "with a ghost part it got to {with_ghost}"
    );
}

#[test]
fn a_translation_locked_bullet_bounces_off_a_tilted_wall_without_leaving_its_axis() {
    // A ball free along x only hits, at 150 m/s, a wall turned 30° about z: the bounce's
    // sideways share must not move it off its axis, in the sweep as in the solver.
    let mut app = common::app();
    app.world_mut().spawn((
        Collider::cuboid(0.005, 10.0, 10.0),
        Position::new(5.0, 0.0, 0.0),
        Rotation(Quat::from_rotation_z(0.5)),
        Static,
        Restitution(1.0),
    ));
    let ball = app
        .world_mut()
        .spawn((
            Collider::sphere(0.05),
            Position::new(0.0, 0.0, 0.0),
            Velocity(Vec3::X * 150.0),
            Restitution(1.0),
            LockedAxes::new().lock_translation_y().lock_translation_z(),
            Ccd,
        ))
        .id();
    for _ in 0..10 {
        urto::step(app.world_mut(), 1).unwrap();
        let p = app.world().get::<Position>(ball).unwrap().0;
        let v = app.world().get::<Velocity>(ball).unwrap().0;
        assert!(
            p.y == 0.0 && p.z == 0.0 && v.y == 0.0 && v.z == 0.0,
            "{p} {v}"
        );
        assert!(p.x < 5.0, "passed the wall: {p}");
    }
    let v = app.world().get::<Velocity>(ball).unwrap().0;
    assert!(v.x < 0.0, "it bounced: {v}");
}

/// Thin bodies (a plate 1 cm thick, a capsule and a stick 2 cm thick, all 1 m across) thrown
/// at the 1 cm wall at 5 and 20 m/s, spinning at 150 rad/s about random axes, unmarked: none
/// passes it. Their centres move less than their bounding radius a substep, but their ends
/// 0.3 m: until automatic continuous collision counted turning (`turns_past_its_thickness`),
/// 15 of these 240 throws passed.
#[test]
fn thin_bodies_spinning_at_150_rad_s_never_pass_a_1cm_wall() {
    let mut rng = Rng::new(29);
    for shape in &common::thin_bodies() {
        for speed in [5.0, 20.0] {
            for throw in 0..40 {
                let (mut app, body) = common::thrown_spinning(shape, (speed, 150.0), &mut rng);
                urto::step(app.world_mut(), 60).unwrap();
                let x = app.world().get::<Position>(body).unwrap().0.x;
                assert!(x < 5.0, "{shape:?} at {speed} m/s, throw {throw}: x = {x}");
            }
        }
    }
}

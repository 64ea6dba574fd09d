//! "Simulate only the effects a scene calls for": an effect absent from the scene never runs.

mod common;

use bevy_ecs::prelude::*;
use glam::Vec3;
use urto::prelude::*;

fn runs(app: &bevy_app::App, effect: &str) -> u64 {
    app.world().resource::<PhysicsStats>().runs(effect)
}

#[test]
fn an_empty_world_runs_no_effect() {
    let mut app = common::app();
    urto::step(app.world_mut(), 10).unwrap();
    for effect in [
        "forces/gravity",
        "forces/user",
        "forces/drag",
        "forces/springs",
        "integrate",
        "broad_phase",
        "narrow_phase",
        "response",
    ] {
        assert_eq!(runs(&app, effect), 0, "{effect} ran in an empty world");
    }
}

#[test]
fn bodies_without_colliders_pay_nothing_for_collision_and_without_gravity_do_not_fall() {
    let mut app = common::legacy_app();
    let body = app
        .world_mut()
        .spawn((Position::new(0.0, 0.0, 5.0), Velocity::new(1.0, 0.0, 0.0)))
        .id();
    urto::step(app.world_mut(), 60).unwrap();
    assert_eq!(runs(&app, "integrate"), 60);
    assert_eq!(runs(&app, "forces/gravity"), 0);
    assert_eq!(runs(&app, "broad_phase"), 0);
    assert_eq!(runs(&app, "narrow_phase"), 0);
    let p = app.world().get::<Position>(body).unwrap().0;
    assert!((p - Vec3::new(1.0, 0.0, 5.0)).length() < 1e-4, "{p}");
}

#[test]
fn each_force_runs_only_when_present() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let a = app.world_mut().spawn(Velocity::default()).id();
    urto::step(app.world_mut(), 5).unwrap();
    assert_eq!(runs(&app, "forces/gravity"), 5);
    assert_eq!(runs(&app, "forces/user"), 0);
    assert_eq!(runs(&app, "forces/springs"), 0);
    assert_eq!(runs(&app, "forces/drag"), 0);

    app.world_mut()
        .entity_mut(a)
        .insert((Force(Vec3::X), LinearDrag(0.1)));
    urto::step(app.world_mut(), 3).unwrap();
    assert_eq!(runs(&app, "forces/user"), 3);
    assert_eq!(runs(&app, "forces/drag"), 3);
    assert_eq!(runs(&app, "forces/springs"), 0);
    // The force was consumed by the first of those steps.
    assert_eq!(app.world().get::<Force>(a).unwrap().0, Vec3::ZERO);
}

#[test]
fn a_force_acts_for_one_step_then_is_cleared() {
    let mut app = common::app();
    let m = 2.0;
    let body = app
        .world_mut()
        .spawn((
            Velocity::default(),
            Mass(m),
            Force(Vec3::new(6.0, 0.0, 0.0)),
        ))
        .id();
    urto::step(app.world_mut(), 10).unwrap();
    let v = app.world().get::<Velocity>(body).unwrap().0;
    // One step of a = F/m = 3 m/s² for dt = 1/60 s.
    assert!((v.x - 3.0 / 60.0).abs() < 1e-6, "{v}");
}

#[test]
fn springs_pull_towards_their_rest_length() {
    let mut app = common::app();
    let anchor = app
        .world_mut()
        .spawn((Position::new(0.0, 0.0, 0.0), Static))
        .id();
    let bob = app
        .world_mut()
        .spawn((
            Position::new(2.0, 0.0, 0.0),
            Velocity::default(),
            Spring {
                target: SpringTarget::Entity(anchor),
                rest_length: 1.0,
                stiffness: 50.0,
                damping: 5.0,
            },
        ))
        .id();
    urto::step(app.world_mut(), 600).unwrap();
    assert_eq!(runs(&app, "forces/springs"), 600);
    let x = app.world().get::<Position>(bob).unwrap().0.x;
    assert!(
        (x - 1.0).abs() < 1e-2,
        "damped spring should settle at rest length: {x}"
    );
}

/// A scene using every stage: ground, a resting ball, a falling box, a pushed ball, a compound
/// with a part, a sensor and a fast CCD ball.
fn busy_scene(app: &mut bevy_app::App) -> [bevy_ecs::entity::Entity; 2] {
    use bevy_ecs::hierarchy::ChildOf;
    app.insert_resource(Gravity::EARTH_Z_UP);
    let world = app.world_mut();
    world.spawn((Collider::half_space(Vec3::Z), Static));
    let resting = world
        .spawn((
            Collider::sphere(0.5),
            Position::new(0.0, 0.0, 0.5),
            Velocity::default(),
        ))
        .id();
    let falling = world
        .spawn((
            Collider::cuboid(0.5, 0.5, 0.5),
            Position::new(3.0, 0.0, 3.0),
            Velocity::default(),
        ))
        .id();
    world.spawn((
        Collider::sphere(0.3),
        Position::new(-3.0, 0.0, 0.3),
        Velocity::default(),
        Force(Vec3::new(5.0, 0.0, 0.0)),
    ));
    let root = world
        .spawn((
            Collider::cuboid(0.2, 0.2, 0.2),
            Position::new(0.0, 4.0, 2.0),
            Velocity::default(),
        ))
        .id();
    world.spawn((
        Collider::sphere(0.2),
        Position::new(0.5, 0.0, 0.0),
        ChildOf(root),
    ));
    world.spawn((
        Collider::cuboid(1.0, 1.0, 1.0),
        Position::new(6.0, 0.0, 1.0),
        Static,
        Sensor,
    ));
    world.spawn((
        Collider::sphere(0.1),
        Position::new(-6.0, 3.0, 1.0),
        Velocity(Vec3::new(200.0, 0.0, 0.0)),
        Ccd,
    ));
    let lamp = world
        .spawn((
            Collider::sphere(0.2),
            Position::new(0.0, -5.0, 3.0),
            Velocity::default(),
        ))
        .id();
    world.spawn(
        Joint::spherical(lamp, JointEnd::World)
            .with_anchors(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, -5.0, 4.0)),
    );
    [resting, falling]
}

#[test]
fn every_one_of_the_17_plugins_can_be_disabled_and_a_busy_scene_steps_without_a_panic_the_ball_resting_within_2_cm()
 {
    use bevy_app::{App, PluginGroup};
    use urto::plugins::*;
    fn without<P: bevy_app::Plugin>() -> App {
        let mut app = App::new();
        app.add_plugins(UrtoPlugins::default().build().disable::<P>());
        app
    }
    type MakeApp = fn() -> App;
    let apps: [(&str, MakeApp); 17] = [
        ("core", without::<PhysicsCorePlugin>),
        ("validation", without::<ValidationPlugin>),
        ("forces", without::<ForcesPlugin>),
        ("integration", without::<IntegrationPlugin>),
        ("mass properties", without::<MassPropertiesPlugin>),
        ("rotation", without::<RotationPlugin>),
        ("hierarchy", without::<HierarchyPlugin>),
        ("broad phase", without::<BroadPhasePlugin>),
        ("ccd", without::<CcdPlugin>),
        ("narrow phase", without::<NarrowPhasePlugin>),
        ("soft step", without::<SoftStepPlugin>),
        ("joints", without::<JointPlugin>),
        ("response", without::<ResponsePlugin>),
        ("sleep", without::<SleepPlugin>),
        ("transform sync", without::<TransformSyncPlugin>),
        ("spatial query", without::<SpatialQueryPlugin>),
        ("interpolation", without::<InterpolationPlugin>),
    ];
    let mut panicked = Vec::new();
    let mut resting = std::collections::BTreeMap::new();
    for (name, make) in apps {
        let outcome = std::panic::catch_unwind(move || {
            let mut app = make();
            let [ball, _] = busy_scene(&mut app);
            let stepped = urto::step(app.world_mut(), 60);
            (
                stepped.is_ok(),
                app.world().get::<Position>(ball).map(|p| p.0.z),
            )
        });
        match outcome {
            Ok(result) => {
                resting.insert(name, result);
            }
            Err(_) => panicked.push(name),
        }
    }
    assert!(panicked.is_empty(), "panicked without: {panicked:?}");
    // Without the core nothing steps, and `step` says so.
    assert!(!resting["core"].0);
    // Without the hierarchy nothing refits the volumes (the broad phase warns), without the
    // broad or narrow phase nothing finds contacts: the ball falls through the ground. With any
    // other stage gone it still rests on the ground.
    let blind = ["hierarchy", "broad phase", "narrow phase"];
    for name in blind {
        assert!(resting[name].0 && resting[name].1.unwrap() < 0.0, "{name}");
    }
    for (name, (stepped, z)) in &resting {
        if *name != "core" && !blind.contains(name) {
            assert!(*stepped, "{name}");
            let z = z.unwrap();
            assert!((z - 0.5).abs() < 0.02, "without {name} the ball is at {z}");
        }
    }
}

/// How many of `walls` each of `balls` is paired with in the last step's broad phase.
fn planes_of(app: &bevy_app::App, walls: &[Entity], balls: &[Entity]) -> Vec<usize> {
    let pairs = &app
        .world()
        .resource::<urto::plugins::BroadPhasePairs>()
        .pairs;
    let count = |ball: &Entity| {
        pairs
            .iter()
            .filter(|(a, b)| a == ball && walls.contains(b))
            .count()
    };
    balls.iter().map(count).collect()
}

#[test]
fn in_a_box_of_six_planes_a_ball_pairs_only_with_the_planes_its_grown_volume_reaches_0_1_or_2() {
    // A wall a body does not reach costs it no narrow-phase pair. In a 10 m box of half-spaces
    // (each wall's solid outside it), without gravity: a ball of radius 0.5 in the middle, one
    // half its margin from the +x wall, one in the corner of +x and +y. Pairing
    // every ball with every plane made 18 pairs; a wall pairs with a ball only where the
    // ball's volume, grown by its speculative margin, reaches it.
    let mut app = common::app();
    app.insert_resource(Gravity::new(Vec3::ZERO).unwrap());
    let mut walls = Vec::new();
    for n in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
        let wall = app
            .world_mut()
            .spawn((Collider::half_space(n), Position(-5.0 * n), Static))
            .id();
        walls.push(wall);
    }
    // At rest without gravity a ball's margin is the fixed distance.
    let near = 4.5 - 0.5 * urto::plugins::SpeculativeMargin::default().distance;
    let balls = [
        common::ball(&mut app, Vec3::ZERO),
        common::ball(&mut app, Vec3::new(near, 0.0, 0.0)),
        common::ball(&mut app, Vec3::new(near, near, 0.0)),
    ];
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(planes_of(&app, &walls, &balls), [0, 1, 2]);
    // The ones it reaches are still met: the balls touch nothing yet, and nothing moved.
    for ball in balls {
        let v = app.world().get::<Velocity>(ball).unwrap().0;
        assert!(v.length() < 1e-6, "{v}");
    }
    // The floor (the -z wall's solid is below z = -5) given a child without a collider (a
    // render mesh in a game) is still culled by its plane; given a child with one (a compound),
    // it is paired with every ball, as any unbounded compound is.
    let floor = walls[2];
    app.world_mut()
        .spawn((Position(Vec3::new(0.0, 0.0, -5.0)), ChildOf(floor)));
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(planes_of(&app, &walls, &balls), [0, 1, 2]);
    app.world_mut().spawn((
        Collider::cuboid(0.5, 0.5, 0.5),
        Position(Vec3::new(0.0, 0.0, -5.0)),
        ChildOf(floor),
    ));
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(planes_of(&app, &walls, &balls), [1, 2, 3]);
}

/// Two boxes floating still 4 mm apart (no gravity, never moving, so nothing re-indexes them
/// for their own sake): with a 1 mm speculative distance per body they are no broad-phase pair;
/// when the game raises it to 2.5 mm (5 mm for the two) they are one at the next step, and
/// again none after it is lowered back.
#[test]
fn a_changed_speculative_margin_regrows_resting_bodies_within_one_step_4_mm_apart() {
    use urto::plugins::SpeculativeMargin;
    let mut app = common::app();
    app.insert_resource(Gravity::new(Vec3::ZERO).unwrap());
    let margin = |d: f32| SpeculativeMargin {
        distance: d,
        ..Default::default()
    };
    app.insert_resource(margin(0.001));
    let still = |app: &mut bevy_app::App, x: f32| {
        let body = (
            Collider::cuboid(0.5, 0.5, 0.5),
            Position::new(x, 0.0, 5.0),
            Velocity::default(),
        );
        app.world_mut().spawn(body).id()
    };
    let (a, b) = (still(&mut app, 0.0), still(&mut app, 1.004));
    let paired = |app: &bevy_app::App| {
        let pairs = &app
            .world()
            .resource::<urto::plugins::BroadPhasePairs>()
            .pairs;
        pairs.iter().any(|&p| p == (a, b) || p == (b, a))
    };
    urto::step(app.world_mut(), 3).unwrap();
    assert!(!paired(&app));
    app.insert_resource(margin(0.0025));
    urto::step(app.world_mut(), 1).unwrap();
    assert!(
        paired(&app),
        "the raised margin did not regrow the resting boxes"
    );
    app.insert_resource(margin(0.001));
    urto::step(app.world_mut(), 1).unwrap();
    assert!(!paired(&app));
}

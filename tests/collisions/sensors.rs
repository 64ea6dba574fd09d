//! Sensors: they report what passes through and rests in them, push nothing, and a fast ball
//! under continuous collision still passes a thin one.

use super::*;

#[test]
fn a_sensor_reports_a_passing_ball_once_each_way_and_leaves_its_velocity_within_1e_6() {
    let mut app = common::app();
    let goal = app
        .world_mut()
        .spawn((
            Collider::cuboid(1.0, 1.0, 1.0),
            Position::new(0.0, 0.0, 0.0),
            Static,
            Sensor,
        ))
        .id();
    let b = ball(
        &mut app,
        Vec3::new(-5.0, 0.0, 0.0),
        Vec3::new(5.0, 0.0, 0.0),
        1.0,
        0.0,
    );
    let mut heard = Heard::new(&app);
    let (mut started, mut ended, mut overlapping_steps) = (Vec::new(), Vec::new(), 0);
    for _ in 0..120 {
        urto::step(app.world_mut(), 1).unwrap();
        let [s, e] = heard.read(&app);
        started.extend(s);
        ended.extend(e);
        let overlaps = app
            .world()
            .resource::<urto::plugins::narrow_phase::SensorOverlaps>();
        overlapping_steps += usize::from(!overlaps.pairs.is_empty());
    }
    assert_eq!(started, [ordered(goal, b)]);
    assert_eq!(ended, [ordered(goal, b)]);
    // Overlapping while the centre is within 1.5 m of the box's centre: 3 m at 5 m/s, 36 steps.
    assert!(
        (35..=38).contains(&overlapping_steps),
        "{overlapping_steps}"
    );
    assert!((velocity(&app, b) - Vec3::new(5.0, 0.0, 0.0)).length() < 1e-6);
    assert!(app.world().get::<Position>(b).unwrap().0.x > 4.9);
}

#[test]
fn a_ball_resting_in_a_sensor_sleeps_and_a_dynamic_sensor_falls_through_the_ground() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let ground = app
        .world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static))
        .id();
    let zone = app
        .world_mut()
        .spawn((
            Collider::cuboid(2.0, 2.0, 1.0),
            Position::new(0.0, 0.0, 1.0),
            Static,
            Sensor,
        ))
        .id();
    let resting = common::ball(&mut app, Vec3::new(0.0, 0.0, 0.5));
    let ghost = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::new(10.0, 0.0, 2.0),
            Velocity::default(),
            Sensor,
        ))
        .id();
    let mut heard = Heard::new(&app);
    let (mut started, mut ended) = (Vec::new(), Vec::new());
    for _ in 0..120 {
        urto::step(app.world_mut(), 1).unwrap();
        let [s, e] = heard.read(&app);
        started.extend(s);
        ended.extend(e);
    }
    assert!(
        app.world().get::<Sleeping>(resting).is_some(),
        "the ball in the zone sleeps"
    );
    assert!(started.contains(&ordered(zone, resting)));
    assert!(
        !ended.contains(&ordered(zone, resting)),
        "sleeping in the zone ends nothing"
    );
    let z = app.world().get::<Position>(ghost).unwrap().0.z;
    assert!(z < -2.0, "the sensor ball fell through the ground: z = {z}");
    // Below the plane it is inside the solid half-space: overlapping still, not ended.
    assert!(started.contains(&ordered(ground, ghost)));
    assert!(!ended.contains(&ordered(ground, ghost)));
    let overlaps = app
        .world()
        .resource::<urto::plugins::narrow_phase::SensorOverlaps>();
    assert!(
        overlaps
            .pairs
            .iter()
            .any(|p| ordered(p.a, p.b) == ordered(ground, ghost))
    );
}

#[test]
fn a_fast_ball_under_ccd_passes_through_a_thin_sensor_wall() {
    let mut app = common::app();
    app.world_mut().spawn((
        Collider::cuboid(0.05, 5.0, 5.0),
        Position::new(0.0, 0.0, 0.0),
        Static,
        Sensor,
    ));
    let fast = app
        .world_mut()
        .spawn((
            Collider::sphere(0.1),
            Position::new(-2.0, 0.0, 0.0),
            Velocity(Vec3::new(300.0, 0.0, 0.0)),
            Ccd,
        ))
        .id();
    urto::step(app.world_mut(), 1).unwrap();
    let x = app.world().get::<Position>(fast).unwrap().0.x;
    assert!(x > 2.5, "{x}");
}

/// A box resting on a slab with a sensor part reaching 10 cm into the slab touches it through
/// two colliders: one collision starts (with the solid part's contact); thrown up at 10 m/s,
/// both parts leave within one substep and one collision ends, and landing starts one again.
/// Each part's start and end used to be reported, two of each (a fifth user-style probe); the
/// two parts leaving together ended it twice until the sensor's end deferred to the contact's.
#[test]
fn a_body_touching_through_a_solid_and_a_sensor_part_starts_and_ends_one_collision_at_a_time() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let floor = app
        .world_mut()
        .spawn((
            Collider::cuboid(20.0, 5.0, 0.5),
            Position::new(0.0, 0.0, -0.5),
            Static,
        ))
        .id();
    let host = app
        .world_mut()
        .spawn((
            Collider::cuboid(0.5, 0.5, 0.3),
            Position::new(0.0, 0.0, 0.3),
            Velocity::default(),
            Restitution(0.0),
        ))
        .id();
    app.world_mut().spawn((
        Collider::cuboid(0.4, 0.4, 0.4),
        Position(Vec3::ZERO),
        Sensor,
        ChildOf(host),
    ));
    let w = app.world();
    let mut starts = w.resource::<Messages<CollisionStarted>>().get_cursor();
    let mut ends = w.resource::<Messages<CollisionEnded>>().get_cursor();
    let mut events = Vec::new();
    let mut listen = |app: &mut bevy_app::App, steps: u32| {
        for _ in 0..steps {
            urto::step(app.world_mut(), 1).unwrap();
            let w = app.world();
            // Within a step the ends come from earlier substeps than a start could follow.
            let e = ends.read(w.resource::<Messages<CollisionEnded>>());
            events.extend(e.map(|m| ("end", (m.a, m.b), false)));
            let s = starts_with_contact(app, &mut starts);
            events.extend(s.iter().map(|m| ("start", (m.a, m.b), m.contact.is_some())));
        }
    };
    listen(&mut app, 60);
    app.world_mut()
        .entity_mut(host)
        .insert(Impulse::new(Vec3::new(0.0, 0.0, 6.0)));
    listen(&mut app, 180);
    let pair = ordered(host, floor);
    assert!(events.iter().all(|(_, p, _)| *p == pair), "{events:?}");
    // Started, ended on the throw, started on landing (a landing at 10 m/s may lift off and
    // land again): never two starts or two ends in a row.
    let kinds: Vec<&str> = events.iter().map(|(k, _, _)| *k).collect();
    assert!(kinds.len() >= 3, "{events:?}");
    for (i, kind) in kinds.iter().enumerate() {
        let expected = if i % 2 == 0 { "start" } else { "end" };
        assert_eq!(*kind, expected, "{events:?}");
    }
    assert!(
        events[0].2,
        "the first start carries the solid part's contact"
    );
}

/// A static zone 2 m across centred 1 m above a floor at `zone_x`, and a box of 0.6 m
/// asleep on the floor at the origin; the app, the zone and the box.
fn box_asleep_by_a_zone(zone_x: f32) -> (bevy_app::App, Entity, Entity) {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let world = app.world_mut();
    let floor = (
        Collider::cuboid(20.0, 5.0, 0.5),
        Position::new(0.0, 0.0, -0.5),
    );
    world.spawn((floor, Static));
    let zone = (
        Collider::cuboid(1.0, 1.0, 1.0),
        Position::new(zone_x, 0.0, 1.0),
    );
    let zone = world.spawn((zone, Static, Sensor)).id();
    let body = (
        Collider::cuboid(0.3, 0.3, 0.3),
        Position::new(0.0, 0.0, 0.3),
    );
    let b = world.spawn((body, Velocity::default())).id();
    urto::step(app.world_mut(), 120).unwrap();
    assert!(app.world().get::<Sleeping>(b).is_some(), "the box sleeps");
    (app, zone, b)
}

/// Steps 3 times; the pairs that started and that ended.
fn heard_in_3_steps(app: &mut bevy_app::App, heard: &mut Heard) -> [Vec<(Entity, Entity)>; 2] {
    let mut all = [Vec::new(), Vec::new()];
    for _ in 0..3 {
        urto::step(app.world_mut(), 1).unwrap();
        for (to, from) in all.iter_mut().zip(heard.read(app)) {
            to.extend(from);
        }
    }
    all
}

/// A box asleep on a floor inside a static zone: the zone moved 10 m away or given layers that
/// keep it from the box ends the overlap within 3 steps, and the zone made solid wakes the box
/// (which it now overlaps). The overlap of a sleeper and a static was never tested again:
/// none of the three was heard while the box slept (a fifth user-style probe).
#[test]
fn a_static_zone_moved_off_a_sleeper_or_made_solid_is_heard_within_3_steps() {
    for change in ["moved", "layers", "solid"] {
        let (mut app, zone, b) = box_asleep_by_a_zone(0.0);
        let mut heard = Heard::new(&app);
        let mut zone_mut = app.world_mut().entity_mut(zone);
        match change {
            "moved" => drop(zone_mut.insert(Position::new(10.0, 0.0, 1.0))),
            "layers" => drop(zone_mut.insert(CollisionLayers::new(LayerMask(2), LayerMask(2)))),
            _ => drop(zone_mut.remove::<Sensor>()),
        }
        let [_, ended] = heard_in_3_steps(&mut app, &mut heard);
        if change == "solid" {
            assert!(app.world().get::<Sleeping>(b).is_none(), "solid: awake");
        } else {
            assert_eq!(ended, [ordered(zone, b)], "{change}");
        }
    }
}

/// A box asleep on a floor: a static zone spawned around it, or moved onto it from 10 m away,
/// starts an overlap within 3 steps, and a static wall spawned through it wakes it. None was
/// seen while the box slept: the new static had no pair with it.
#[test]
fn a_static_zone_spawned_or_moved_onto_a_sleeper_is_heard_within_3_steps() {
    for change in ["spawned", "moved onto", "wall"] {
        let (mut app, away, b) = box_asleep_by_a_zone(10.0);
        let mut heard = Heard::new(&app);
        let around = Position::new(0.0, 0.0, 1.0);
        let zone = match change {
            "spawned" => {
                let zone = (Collider::cuboid(1.0, 1.0, 1.0), around, Static, Sensor);
                app.world_mut().spawn(zone).id()
            }
            "moved onto" => {
                app.world_mut().entity_mut(away).insert(around);
                away
            }
            _ => {
                let wall = (Collider::cuboid(0.1, 2.0, 2.0), around, Static);
                app.world_mut().spawn(wall).id()
            }
        };
        let [started, _] = heard_in_3_steps(&mut app, &mut heard);
        if change == "wall" {
            assert!(app.world().get::<Sleeping>(b).is_none(), "wall: awake");
        } else {
            assert_eq!(started, [ordered(zone, b)], "{change}");
        }
    }
}

/// A sensor weighs nothing (as in Avian, Godot and Unity): a 1 × 1 × 0.6 m box (0.6 kg at
/// 1 kg/m³) carrying a sensor ball of radius 2 m beside it weighs 0.6 kg with its centre of
/// mass at the box's, within 1e-5; the ball made solid adds its 33.5 kg. A body of sensors
/// alone still weighs them. The ball used to weigh 33.5 kg from the start (a user-style probe).
#[test]
fn a_sensor_part_adds_no_mass_within_1e_5_until_it_is_made_solid() {
    let mut app = common::app();
    let host = app
        .world_mut()
        .spawn((
            Collider::cuboid(0.5, 0.5, 0.3),
            Position::new(0.0, 0.0, 5.0),
            Velocity::default(),
        ))
        .id();
    let zone = (Collider::sphere(2.0), Position::new(3.0, 0.0, 0.0));
    let zone = app.world_mut().spawn((zone, Sensor, ChildOf(host))).id();
    let lone = (Collider::sphere(1.0), Position::new(20.0, 0.0, 5.0));
    let lone = app
        .world_mut()
        .spawn((lone, Velocity::default(), Sensor))
        .id();
    urto::step(app.world_mut(), 1).unwrap();
    let mass = |app: &bevy_app::App, e| app.world().get::<ComputedMass>(e).unwrap().value();
    assert!(
        (mass(&app, host) - 0.6).abs() < 1e-5,
        "{}",
        mass(&app, host)
    );
    let center = app
        .world()
        .get::<Inertia>(host)
        .unwrap()
        .local_center_of_mass;
    assert!(center.length() < 1e-5, "centre of mass {center}");
    let ball = 4.0 / 3.0 * std::f32::consts::PI;
    assert!(
        (mass(&app, lone) - ball).abs() < 1e-4,
        "{}",
        mass(&app, lone)
    );
    app.world_mut().entity_mut(zone).remove::<Sensor>();
    urto::step(app.world_mut(), 1).unwrap();
    let solid = 0.6 + 8.0 * ball;
    assert!(
        (mass(&app, host) - solid).abs() < 1e-3,
        "{}",
        mass(&app, host)
    );
}

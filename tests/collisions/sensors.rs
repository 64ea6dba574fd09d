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

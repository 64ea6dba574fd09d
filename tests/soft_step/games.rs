//! What games lean on: collision starts, waking, rolling resistance, dominoes, bad materials
//! and margins contained, and a contact hook making a one-way platform.

use super::*;

#[test]
fn with_the_soft_step_a_ball_caught_within_a_step_reports_one_collision_start() {
    let mut app = soft_step_app();
    app.world_mut().spawn((
        Collider::cuboid(0.5, 5.0, 5.0),
        Position::new(3.0, 0.0, 0.0),
        Static,
    ));
    app.world_mut().spawn((
        Collider::sphere(0.5),
        Position::new(0.0, 0.0, 0.0),
        Velocity::new(40.0, 0.0, 0.0),
        Restitution(0.0),
    ));
    let mut cursor = app
        .world()
        .resource::<bevy_ecs::message::Messages<CollisionStarted>>()
        .get_cursor();
    let mut started = 0;
    for _ in 0..30 {
        urto::step(app.world_mut(), 1).unwrap();
        let messages = app
            .world()
            .resource::<bevy_ecs::message::Messages<CollisionStarted>>();
        started += cursor.read(messages).count();
    }
    assert_eq!(started, 1);
}

#[test]
fn with_the_soft_step_a_ball_dropped_on_a_sleeping_ball_wakes_it() {
    let mut app = soft_step_app_on_ground();
    app.insert_resource(SleepSettings {
        enabled: true,
        ..Default::default()
    });
    let below = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::new(0.0, 0.0, 0.5),
            Velocity::default(),
        ))
        .id();
    urto::step(app.world_mut(), 60).unwrap();
    assert!(
        app.world().get::<Sleeping>(below).is_some(),
        "did not fall asleep"
    );
    app.world_mut().spawn((
        Collider::sphere(0.5),
        Position::new(0.3, 0.0, 3.0),
        Velocity::default(),
    ));
    let mut woke = false;
    for _ in 0..60 {
        urto::step(app.world_mut(), 1).unwrap();
        woke |= app.world().get::<Sleeping>(below).is_none();
    }
    assert!(woke, "the ball below slept through the hit");
    let moved = get::<Position>(&app, below).0 - Vec3::new(0.0, 0.0, 0.5);
    assert!(
        moved.x < -0.01,
        "pushed aside by the off-centre hit: moved {moved}"
    );
}

/// How far a solid ball rolling at 2 m/s on flat ground gets in 5 s with rolling resistance `b`.
fn rolled(b: Option<f32>) -> f32 {
    let mut app = soft_step_app();
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static, Friction(1.0)));
    let mut ball = app.world_mut().spawn((
        Collider::sphere(0.5),
        Position::new(0.0, 0.0, 0.5),
        Velocity::new(2.0, 0.0, 0.0),
        AngularVelocity(Vec3::new(0.0, 4.0, 0.0)),
        Friction(1.0),
    ));
    if let Some(b) = b {
        ball.insert(RollingResistance(b));
    }
    let ball = ball.id();
    urto::step(app.world_mut(), 300).unwrap();
    get::<Position>(&app, ball).0.x
}

#[test]
fn with_the_soft_step_rolling_resistance_stops_a_ball_at_the_analytic_distance_within_3_percent() {
    // Torque b·m·g against rolling: a = (b/R) g / (1 + 2/5), stopping after v² / 2a.
    let (b, r, v) = (0.05f32, 0.5f32, 2.0f32);
    let g = Gravity::EARTH_Z_UP.acceleration().length();
    let a = (b / r) * g / 1.4;
    let expected = v * v / (2.0 * a);
    let distance = rolled(Some(b));
    assert!(
        (distance / expected - 1.0).abs() < 0.03,
        "stopped after {distance} m, analytic {expected} m"
    );
    // Without it the ball keeps rolling: 10 m in 5 s.
    let free = rolled(None);
    assert!((free / 10.0 - 1.0).abs() < 0.01, "rolled {free} m freely");
}

#[test]
fn with_the_soft_step_50_dominoes_topple_in_order_each_within_2_s_of_the_one_before() {
    let mut app = soft_step_app();
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static, Friction(0.6)));
    // Dominoes 1 m tall, 0.5 m wide and 0.1 m thick, 0.5 m apart along x.
    let dominoes: Vec<Entity> = (0..50)
        .map(|i| {
            app.world_mut()
                .spawn((
                    Collider::cuboid(0.05, 0.25, 0.5),
                    Position::new(0.5 * i as f32, 0.0, 0.5),
                    Velocity::default(),
                    Friction(0.6),
                    Restitution(0.0),
                ))
                .id()
        })
        .collect();
    // Tip the first one towards the others.
    app.world_mut()
        .entity_mut(dominoes[0])
        .insert(AngularVelocity(Vec3::new(0.0, 2.0, 0.0)));
    let mut fell_at: Vec<Option<f32>> = vec![None; dominoes.len()];
    for step in 1..=900 {
        urto::step(app.world_mut(), 1).unwrap();
        for (i, &d) in dominoes.iter().enumerate() {
            let up = get::<Rotation>(&app, d).0 * Vec3::Z;
            if fell_at[i].is_none() && up.z < 0.7 {
                fell_at[i] = Some(step as f32 / 60.0);
            }
        }
    }
    let times: Vec<f32> = fell_at
        .iter()
        .enumerate()
        .map(|(i, t)| t.unwrap_or_else(|| panic!("domino {i} still stands")))
        .collect();
    eprintln!(
        "dominoes fell from {} s to {} s",
        times[0],
        times[times.len() - 1]
    );
    for (i, w) in times.windows(2).enumerate() {
        assert!(
            w[1] >= w[0] && w[1] - w[0] < 2.0,
            "domino {} fell at {} s after domino {i} at {} s",
            i + 1,
            w[1],
            w[0]
        );
    }
    // And they fell forwards, along +x.
    for &d in &dominoes {
        let up = get::<Rotation>(&app, d).0 * Vec3::Z;
        assert!(up.x > 0.5, "a domino fell sideways or backwards: up {up}");
    }
}

#[test]
fn with_the_soft_step_a_nan_or_negative_rolling_resistance_counts_as_none_and_stays_in_its_body() {
    // A bad lever arm is no resistance: the ball rolls as a free one does, within 1 %.
    let free = rolled(None);
    for bad in [f32::NAN, -1.0, f32::INFINITY] {
        let distance = rolled(Some(bad));
        assert!(
            distance.is_finite() && (distance / free - 1.0).abs() < 0.01,
            "RollingResistance({bad}): rolled {distance} m, a free ball {free} m"
        );
    }
}

#[test]
fn with_the_soft_step_an_unusable_speculative_margin_leaves_a_dropped_ball_resting_within_1_cm() {
    for margin in [
        SpeculativeMargin {
            distance: f32::NAN,
            reach_ratio: f32::INFINITY,
        },
        SpeculativeMargin {
            distance: -1.0,
            reach_ratio: -1.0,
        },
    ] {
        let mut app = soft_step_app_on_ground();
        app.insert_resource(margin);
        let ball = app
            .world_mut()
            .spawn((
                Collider::sphere(0.5),
                Position::new(0.0, 0.0, 2.0),
                Velocity::default(),
            ))
            .id();
        urto::step(app.world_mut(), 180).unwrap();
        let z = get::<Position>(&app, ball).0.z;
        assert!((z - 0.5).abs() < 0.01, "{margin:?}: ball at {z}");
    }
}

/// A platform a body passes through from below and lands on from above.
#[derive(Component)]
struct OneWay;

/// The hook: a pair with a one-way platform stays only while the other body is above the
/// platform's top.
fn one_way_platforms(
    mut contacts: ResMut<urto::plugins::Contacts>,
    platforms: Query<(&Position, &Collider), With<OneWay>>,
    positions: Query<&Position>,
) {
    contacts.pairs.retain(|p| {
        let (platform, other) = if platforms.contains(p.b) {
            (p.b, p.a)
        } else if platforms.contains(p.a) {
            (p.a, p.b)
        } else {
            return true;
        };
        let (at, collider) = platforms.get(platform).unwrap();
        let top = at.0.z + collider.shape.world_aabb(&Default::default()).max.z;
        positions.get(other).is_ok_and(|p| p.0.z > top)
    });
}

#[test]
fn a_contact_hook_makes_a_one_way_platform_a_ball_jumps_through_and_lands_on_within_1_cm() {
    let run = |hooked: bool| {
        let mut app = soft_step_app_on_ground();
        if hooked {
            app.add_systems(
                urto::schedule::SubstepSchedule,
                one_way_platforms.in_set(urto::plugins::ContactHooks),
            );
        }
        app.world_mut().spawn((
            Collider::cuboid(2.0, 2.0, 0.1),
            Position::new(0.0, 0.0, 2.0),
            Static,
            OneWay,
        ));
        let ball = app
            .world_mut()
            .spawn((
                Collider::sphere(0.25),
                Position::new(0.0, 0.0, 1.0),
                Velocity::new(0.0, 0.0, 8.0),
            ))
            .id();
        urto::step(app.world_mut(), 240).unwrap();
        app.world().get::<Position>(ball).unwrap().0.z
    };
    // Hooked: through the platform on the way up, onto it on the way down (top 2.1 + 0.25).
    let z = run(true);
    assert!((z - 2.35).abs() < 0.01, "hooked: {z}");
    // Without the hook the platform's underside sends it back to the ground.
    let z = run(false);
    assert!((z - 0.25).abs() < 0.01, "plain: {z}");
}

//! Bodies that turn, through the ECS: free tumbling against Euler's equations (angular momentum,
//! the Dzhanibekov flip and its analytic period), torques and forces at points, locked axes,
//! computed and custom inertia (compounds over the scene graph), turning about an off-origin
//! centre of mass, sleeping and bad input.

mod common;

use bevy_app::App;
use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use urto::prelude::*;

fn app_without_gravity() -> App {
    common::app()
}

fn get<T: Component + Copy>(app: &App, e: Entity) -> T {
    *app.world().get::<T>(e).expect("component present")
}

/// World angular momentum `R diag(I) Rᵀ ω` of a body.
fn angular_momentum(app: &App, e: Entity) -> Vec3 {
    let r = get::<Rotation>(app, e).0 * get::<Inertia>(app, e).frame;
    let i = get::<Inertia>(app, e).principal;
    r * ((r.inverse() * get::<AngularVelocity>(app, e).0) * i)
}

/// Angular velocity in the body's principal axes.
fn body_rates(app: &App, e: Entity) -> Vec3 {
    let r = get::<Rotation>(app, e).0 * get::<Inertia>(app, e).frame;
    r.inverse() * get::<AngularVelocity>(app, e).0
}

/// A 1 kg ball of radius 0.5 (I = 0.1 kg m²), whatever its volume would weigh.
fn ball(app: &mut App, at: Vec3) -> Entity {
    let body = (Collider::sphere(0.5), Position(at), Velocity::default());
    app.world_mut().spawn((body, Mass(1.0))).id()
}

fn spinning_box(app: &mut App, half: Vec3, w: Vec3) -> Entity {
    app.world_mut()
        .spawn((
            Collider::cuboid(half.x, half.y, half.z),
            Position::default(),
            Rotation(Quat::from_rotation_x(0.4) * Quat::from_rotation_y(-0.2)),
            Velocity::default(),
            AngularVelocity(w),
            Mass(2.0),
        ))
        .id()
}

#[test]
fn a_box_gets_the_inertia_m_over_12_of_its_sides_within_1e_5() {
    let mut app = app_without_gravity();
    let b = spinning_box(&mut app, Vec3::new(0.5, 0.25, 0.1), Vec3::ZERO);
    urto::step(app.world_mut(), 1).unwrap();
    let inertia = get::<Inertia>(&app, b);
    let (x, y, z) = (1.0f32, 0.5f32, 0.2f32);
    let mut expected = [
        2.0 / 12.0 * (y * y + z * z),
        2.0 / 12.0 * (x * x + z * z),
        2.0 / 12.0 * (x * x + y * y),
    ];
    let mut got = inertia.principal.to_array();
    expected.sort_by(f32::total_cmp);
    got.sort_by(f32::total_cmp);
    for (g, e) in got.iter().zip(expected) {
        assert!((g - e).abs() < 1e-5 * e.max(1.0), "{got:?} vs {expected:?}");
    }
    assert!(inertia.local_center_of_mass.length() < 1e-6);
    assert!(!inertia.custom);
}

#[test]
fn a_tumbling_box_keeps_its_angular_momentum_within_1e_5_over_10_s() {
    let mut app = app_without_gravity();
    let b = spinning_box(
        &mut app,
        Vec3::new(0.5, 0.25, 0.1),
        Vec3::new(1.0, 2.0, 3.0),
    );
    urto::step(app.world_mut(), 1).unwrap();
    let l0 = angular_momentum(&app, b);
    urto::step(app.world_mut(), 600).unwrap();
    let drift = (angular_momentum(&app, b) - l0).length() / l0.length();
    assert!(drift < 1e-5, "relative drift {drift}");
    // It really tumbles: the world angular velocity is not constant for a box.
    assert!((get::<AngularVelocity>(&app, b).0 - Vec3::new(1.0, 2.0, 3.0)).length() > 0.1);
}

/// The complete elliptic integral of the first kind `K(k)` by the arithmetic–geometric mean.
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..40 {
        let (an, bn) = (0.5 * (a + b), (a * b).sqrt());
        a = an;
        b = bn;
    }
    std::f64::consts::PI / (2.0 * a)
}

/// Period of the body-frame angular velocity of a free body with moments `i1 < i2 < i3` (Landau
/// & Lifshitz, *Mechanics*, §37): `4K(k) / λ` with the elliptic modulus of the motion.
fn euler_period(i: [f64; 3], w: [f64; 3]) -> f64 {
    let e2: f64 = (0..3).map(|k| i[k] * w[k] * w[k]).sum();
    let m2: f64 = (0..3).map(|k| (i[k] * w[k]).powi(2)).sum();
    let [i1, i2, i3] = if m2 > e2 * i[1] {
        i
    } else {
        [i[2], i[1], i[0]]
    };
    let k2 = (i2 - i1) * (e2 * i3 - m2) / ((i3 - i2) * (m2 - e2 * i1));
    let lambda = ((i3 - i2) * (m2 - e2 * i1) / (i1 * i2 * i3)).sqrt();
    4.0 * elliptic_k(k2.sqrt()) / lambda
}

/// The measured period of the intermediate-axis flip against the analytic one, with `method`.
fn dzhanibekov_period_error(method: Integrator) -> f64 {
    let mut app = app_without_gravity();
    app.insert_resource(Integration(method));
    let half = Vec3::new(0.6, 0.35, 0.1);
    let b = spinning_box(&mut app, half, Vec3::ZERO);
    urto::step(app.world_mut(), 1).unwrap();
    let inertia = get::<Inertia>(&app, b);
    // Principal rates: mostly about the intermediate axis, a nudge about the others.
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &c| inertia.principal[a].total_cmp(&inertia.principal[c]));
    let mut local = Vec3::ZERO;
    local[order[0]] = 0.02;
    local[order[1]] = 3.0;
    local[order[2]] = 0.02;
    let frame = get::<Rotation>(&app, b).0 * inertia.frame;
    app.world_mut().get_mut::<AngularVelocity>(b).unwrap().0 = frame * local;
    let moments = order.map(|k| inertia.principal[k] as f64);
    let rates = order.map(|k| local[k] as f64);
    let period = euler_period(moments, rates);

    let dt = 1.0 / 60.0;
    let mut crossings = Vec::new();
    let mut last = body_rates(&app, b)[order[1]];
    for n in 1..=(3.5 * period / dt as f64) as usize {
        urto::step(app.world_mut(), 1).unwrap();
        let now = body_rates(&app, b)[order[1]];
        if now.signum() != last.signum() {
            let t = (n as f32 - now / (now - last)) * dt;
            crossings.push(t as f64);
        }
        last = now;
    }
    assert!(
        crossings.len() >= 4,
        "{method:?}: only {} flips",
        crossings.len()
    );
    // ω along the intermediate axis goes as sn: it changes sign every half period.
    let spacing = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    let measured = 2.0 * spacing;
    eprintln!("Dzhanibekov, {method:?}: period {measured:.4} s vs analytic {period:.4} s");
    (measured / period - 1.0).abs()
}

#[test]
fn a_box_spun_about_its_intermediate_axis_flips_with_the_analytic_period_within_5_percent() {
    for method in Integrator::ALL {
        let error = dzhanibekov_period_error(method);
        assert!(
            error < 0.05,
            "{method:?}: period off by {:.2}%",
            error * 100.0
        );
    }
}

#[test]
fn a_torque_gives_alpha_tau_over_i_and_locked_axes_refuse_it() {
    let mut app = app_without_gravity();
    let free = ball(&mut app, Vec3::ZERO);
    let locked = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::new(5.0, 0.0, 0.0),
            Velocity::default(),
            Mass(1.0),
            LockedAxes::ROTATION_LOCKED,
        ))
        .id();
    for _ in 0..60 {
        for e in [free, locked] {
            app.world_mut().entity_mut(e).insert(Torque(Vec3::Z * 0.1));
        }
        urto::step(app.world_mut(), 1).unwrap();
    }
    // 1 kg ball of radius 0.5: I = 0.1 kg m², α = 1 rad/s², ω(1 s) = 1 rad/s.
    let w = get::<AngularVelocity>(&app, free).0;
    assert!((w - Vec3::Z).length() < 1e-4, "{w}");
    assert_eq!(get::<AngularVelocity>(&app, locked).0, Vec3::ZERO);
    assert_eq!(get::<Rotation>(&app, locked).0, Quat::IDENTITY);
}

#[test]
fn a_force_at_a_point_pushes_and_turns_within_1e_4() {
    let mut app = app_without_gravity();
    let b = ball(&mut app, Vec3::new(1.0, 2.0, 3.0));
    let mut push = ForceAtPoint::default();
    // 6 N along x, applied 0.5 m above the centre: torque 3 N m about +y.
    push.add(Vec3::X * 6.0, Vec3::new(1.0, 2.0, 3.5));
    app.world_mut().entity_mut(b).insert(push);
    urto::step(app.world_mut(), 1).unwrap();
    let dt = 1.0 / 60.0;
    let v = get::<Velocity>(&app, b).0;
    let w = get::<AngularVelocity>(&app, b).0;
    assert!((v - Vec3::X * 6.0 * dt).length() < 1e-4, "{v}");
    assert!((w - Vec3::Y * 3.0 / 0.1 * dt).length() < 1e-4, "{w}");
    assert!(
        get::<ForceAtPoint>(&app, b).is_empty(),
        "consumed by the step"
    );
}

#[test]
fn a_custom_inertia_is_kept_and_used() {
    let mut app = app_without_gravity();
    let b = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::default(),
            Velocity::default(),
            Inertia::custom(Vec3::splat(2.0), Quat::IDENTITY),
        ))
        .id();
    app.world_mut().entity_mut(b).insert(Torque(Vec3::X * 2.0));
    urto::step(app.world_mut(), 1).unwrap();
    assert_eq!(get::<Inertia>(&app, b).principal, Vec3::splat(2.0));
    let w = get::<AngularVelocity>(&app, b).0;
    assert!((w.x - 1.0 / 60.0).abs() < 1e-6, "{w}");
}

/// Two unit boxes side by side as a compound: a root box at the origin and a child 1 m along x.
#[test]
fn a_compound_turns_about_its_centre_of_mass_with_the_parallel_axis_inertia_within_1e_4() {
    let mut app = app_without_gravity();
    let root = app
        .world_mut()
        .spawn((
            Collider::cuboid(0.5, 0.5, 0.5),
            Position::new(0.0, 0.0, 0.0),
            Velocity::default(),
            Mass(2.0),
        ))
        .id();
    app.world_mut().spawn((
        Collider::cuboid(0.5, 0.5, 0.5),
        Position::new(1.0, 0.0, 0.0),
        ChildOf(root),
    ));
    urto::step(app.world_mut(), 1).unwrap();
    let inertia = get::<Inertia>(&app, root);
    assert!((inertia.local_center_of_mass - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-5);
    // A 2 x 1 x 1 box of 2 kg: about its long axis m/12 (1+1) = 1/3, across it m/12 (4+1) = 5/6.
    let mut moments = inertia.principal.to_array();
    moments.sort_by(f32::total_cmp);
    let expected = [1.0 / 3.0, 5.0 / 6.0, 5.0 / 6.0];
    for (m, e) in moments.iter().zip(expected) {
        assert!((m - e).abs() < 1e-4, "{moments:?}");
    }
    // Spun about z, the centre of mass stays put while the origin circles it.
    app.world_mut().get_mut::<AngularVelocity>(root).unwrap().0 = Vec3::Z * std::f32::consts::PI;
    urto::step(app.world_mut(), 60).unwrap();
    let p = get::<Position>(&app, root).0;
    let r = get::<Rotation>(&app, root).0;
    let center = p + r * inertia.local_center_of_mass;
    assert!(
        (center - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-4,
        "{center}"
    );
    // Half a turn: the origin is now on the other side of the centre.
    assert!((p - Vec3::new(1.0, 0.0, 0.0)).length() < 1e-3, "{p}");
}

#[test]
fn a_kinematic_spinner_turns_at_its_rate_within_1e_5_rad_whatever_the_torque() {
    let mut app = app_without_gravity();
    let b = app
        .world_mut()
        .spawn((
            Collider::cuboid(1.0, 0.1, 0.1),
            Position::default(),
            Velocity::default(),
            Mass::INFINITE,
            AngularVelocity(Vec3::Z * 0.5),
        ))
        .id();
    for _ in 0..120 {
        app.world_mut()
            .entity_mut(b)
            .insert(Torque(Vec3::X * 100.0));
        urto::step(app.world_mut(), 1).unwrap();
    }
    assert_eq!(get::<AngularVelocity>(&app, b).0, Vec3::Z * 0.5);
    let (q, expected) = (get::<Rotation>(&app, b).0, Quat::from_rotation_z(1.0));
    // |q − q'| is about half the angle between them (acos loses precision this close to 1).
    let angle = 2.0 * (q - expected).length().min((q + expected).length());
    assert!(angle < 1e-5, "{angle}");
}

#[test]
fn drag_decays_the_spin_as_e_to_minus_ct_within_1e_3() {
    let mut app = app_without_gravity();
    let b = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::default(),
            Velocity::default(),
            AngularVelocity(Vec3::Y * 2.0),
            AngularDrag(0.7),
        ))
        .id();
    urto::step(app.world_mut(), 120).unwrap();
    let w = get::<AngularVelocity>(&app, b).0.length();
    let expected = 2.0 * (-0.7f32 * 2.0).exp();
    assert!((w / expected - 1.0).abs() < 1e-3, "{w} vs {expected}");
}

#[test]
fn bad_rotational_input_is_quarantined_and_spreads_nothing() {
    let mut app = app_without_gravity();
    let bad = [
        (AngularVelocity(Vec3::NAN), None, None),
        (AngularVelocity(Vec3::ZERO), Some(AngularDrag(-1.0)), None),
        (
            AngularVelocity(Vec3::ZERO),
            None,
            Some(Inertia::custom(Vec3::new(1.0, 0.0, 1.0), Quat::IDENTITY)),
        ),
    ];
    let mut bodies = Vec::new();
    for (i, (w, drag, inertia)) in bad.into_iter().enumerate() {
        let mut e = app.world_mut().spawn((
            Collider::sphere(0.5),
            Position::new(i as f32 * 3.0, 0.0, 0.0),
            Velocity::default(),
            w,
        ));
        if let Some(d) = drag {
            e.insert(d);
        }
        if let Some(inertia) = inertia {
            e.insert(inertia);
        }
        bodies.push(e.id());
    }
    let torqued = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::new(20.0, 0.0, 0.0),
            Velocity::default(),
            Torque(Vec3::new(f32::INFINITY, 0.0, 0.0)),
        ))
        .id();
    bodies.push(torqued);
    let mut nan_push = ForceAtPoint::default();
    nan_push.add(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::ZERO);
    let pushed = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::new(30.0, 0.0, 0.0),
            Velocity::default(),
            nan_push,
        ))
        .id();
    bodies.push(pushed);
    let good = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::new(0.0, 10.0, 0.0),
            Velocity::default(),
            AngularVelocity(Vec3::X),
        ))
        .id();
    urto::step(app.world_mut(), 10).unwrap();
    for e in bodies {
        assert!(
            app.world().get::<Quarantined>(e).is_some(),
            "{e} not quarantined"
        );
    }
    assert!(app.world().get::<Quarantined>(good).is_none());
    assert!(get::<Rotation>(&app, good).0.is_finite());
}

#[test]
fn a_spinning_ball_stays_awake_and_setting_a_spin_wakes_a_sleeper() {
    // Sleeping is on by default.
    let mut app = common::on_ground(common::app());
    let spinner = app
        .world_mut()
        .spawn((
            Collider::sphere(0.5),
            Position::new(0.0, 0.0, 0.5),
            Velocity::default(),
            AngularVelocity(Vec3::Z * 5.0),
        ))
        .id();
    let still = ball(&mut app, Vec3::new(3.0, 0.0, 0.5));
    urto::step(app.world_mut(), 120).unwrap();
    assert!(
        app.world().get::<Sleeping>(spinner).is_none(),
        "a spinning top sleeps"
    );
    assert!(app.world().get::<Sleeping>(still).is_some());
    app.world_mut().get_mut::<AngularVelocity>(still).unwrap().0 = Vec3::X;
    urto::step(app.world_mut(), 1).unwrap();
    assert!(
        app.world().get::<Sleeping>(still).is_none(),
        "a spin did not wake it"
    );
    assert_ne!(get::<Rotation>(&app, still).0, Quat::IDENTITY);
}

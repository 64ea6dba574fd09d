//! `LengthUnit`: a scene scaled by `s`, with gravity scaled by `s` and the unit set to `s`,
//! moves as the metre-sized scene scaled by `s`, sleeping included.

use super::*;

/// A ball dropped onto a floor (restitution 0.5), a ball rolling at a diameter a second and a
/// box sliding at two widths a second (friction 0.5), all `size` across, under `size × g`,
/// with the unit `unit`; every 10th step's positions over 3 s divided by `size`, and which
/// bodies sleep.
fn scaled_scene(size: f32, unit: f32) -> Vec<(Vec<Vec3>, Vec<bool>)> {
    let mut app = soft_step_app();
    app.insert_resource(Gravity::new(Vec3::new(0.0, 0.0, -9.81 * size)).unwrap())
        .insert_resource(LengthUnit::new(unit).unwrap())
        .insert_resource(ContactSettings {
            default_restitution: 0.0,
            ..Default::default()
        });
    let world = app.world_mut();
    let half = 0.5 * size;
    world.spawn((
        Collider::cuboid(20.0 * size, 20.0 * size, half),
        Position(Vec3::new(0.0, 0.0, -half)),
        Static,
    ));
    let at = |x: f32, z: f32| Position(Vec3::new(x, 0.0, z) * size);
    let bodies = [
        world
            .spawn((
                Collider::sphere(half),
                at(-4.0, 1.5),
                Velocity(Vec3::ZERO),
                Restitution(0.5),
            ))
            .id(),
        world
            .spawn((
                Collider::sphere(half),
                at(0.0, 0.5),
                Velocity(Vec3::X * size),
            ))
            .id(),
        world
            .spawn((
                Collider::cuboid(half, half, half),
                at(4.0, 0.5),
                Velocity(Vec3::X * 2.0 * size),
                Friction(0.5),
            ))
            .id(),
    ];
    let mut frames = Vec::new();
    for _ in 0..18 {
        urto::step(app.world_mut(), 10).unwrap();
        let at = bodies.map(|b| get::<Position>(&app, b).0 / size).to_vec();
        let asleep = bodies.map(|b| app.world().get::<Sleeping>(b).is_some());
        frames.push((at, asleep.to_vec()));
    }
    frames
}

/// The largest gap (in sizes) between two runs' positions, and whether they slept alike.
fn apart(a: &[(Vec<Vec3>, Vec<bool>)], b: &[(Vec<Vec3>, Vec<bool>)]) -> (f32, bool) {
    let gap = a
        .iter()
        .zip(b)
        .flat_map(|(x, y)| x.0.iter().zip(&y.0).map(|(p, q)| p.distance(*q)))
        .fold(0.0, f32::max);
    (gap, a.iter().zip(b).all(|(x, y)| x.1 == y.1))
}

/// 1 cm and 100 m bodies with the unit set to their size follow the 1 m scene within a
/// thousandth of their size and sleep when it does (measured: 1.6e-5 and 2.9e-6). With the
/// unit left at 1, the 1 cm scene ends 1.8 sizes off (its ball lands at 0.3 m/s, under the
/// 1 m/s threshold, and does not bounce; the rolling ball falls asleep) and the 100 m one
/// 0.014 (its ball bounces on where the metre one stopped).
#[test]
fn a_scene_scaled_with_its_length_unit_moves_as_the_metre_scene_within_1e_3_of_a_size() {
    let metre = scaled_scene(1.0, 1.0);
    let asleep = &metre.last().unwrap().1;
    assert_eq!(
        asleep,
        &[true, false, true],
        "dropped ball and box asleep, roller awake"
    );
    for size in [0.01, 100.0] {
        let (gap, same_sleep) = apart(&scaled_scene(size, size), &metre);
        assert!(
            gap < 1e-3 && same_sleep,
            "size {size}: {gap} sizes apart, sleep alike {same_sleep}"
        );
    }
    for (size, most) in [(0.01, 0.1), (100.0, 1e-3)] {
        let (gap, _) = apart(&scaled_scene(size, 1.0), &metre);
        assert!(gap > most, "unit 1 at size {size}: only {gap} sizes apart");
    }
}

/// A length unit outside a micrometre to a thousand kilometres, or not finite, is refused.
#[test]
fn a_length_unit_that_is_not_finite_or_outside_1e_minus_6_to_1e6_is_refused() {
    for bad in [0.0, -1.0, 1e-7, 2e6, f32::NAN, f32::INFINITY] {
        assert!(LengthUnit::new(bad).is_err(), "{bad} accepted");
    }
    assert_eq!(LengthUnit::new(0.01).map(LengthUnit::get), Ok(0.01));
}

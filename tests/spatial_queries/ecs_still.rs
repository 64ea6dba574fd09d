//! The ECS query index's still group: settled static bodies are read again only when the set
//! of settled bodies changes, and the answers stay those of a fresh index over the world
//! while the game moves, turns, reshapes, despawns, spawns, quarantines and un-statics them.

use super::*;
use urto::plugins::SpatialQueryIndex;

/// Every collider of the world (flat roots) at its position, as `(entity, shape, pose)`.
fn world_colliders(world: &mut World) -> Vec<(Entity, Shape, Isometry)> {
    let mut q = world
        .query_filtered::<(Entity, &Collider, &Position, Option<&Rotation>), Without<Quarantined>>(
        );
    let mut out: Vec<_> = q
        .iter(world)
        .map(|(e, c, p, r)| {
            let pose = Isometry::new(p.0, r.map_or(glam::Quat::IDENTITY, |r| r.0));
            (e, c.shape.clone(), pose)
        })
        .collect();
    out.sort_by_key(|(e, ..)| *e);
    out
}

/// What `SpatialQuery` answers to `rays` (every hit: entity and distance) and `boxes`
/// (overlapping entities, sorted).
type Answers = (Vec<Vec<(Entity, f32)>>, Vec<Vec<Entity>>);

fn ecs_answers(app: &mut App, rays: &[Ray], boxes: &[Isometry], refresh: bool) -> Answers {
    let (rays, boxes) = (rays.to_vec(), boxes.to_vec());
    app.world_mut()
        .run_system_once(move |q: SpatialQuery| {
            if refresh {
                q.refresh();
            }
            let all = SpatialQueryFilter::default();
            let hits = rays
                .iter()
                .map(|r| {
                    let hits = q
                        .cast_ray_all(r.origin(), r.direction(), 60.0, &all)
                        .unwrap();
                    hits.iter().map(|h| (h.entity, h.distance)).collect()
                })
                .collect();
            let shape = Shape::cuboid(Vec3::new(2.0, 3.0, 1.5));
            let overlaps = boxes
                .iter()
                .map(|pose| {
                    let mut found = q.overlapping(&shape, *pose, &all).unwrap();
                    found.sort();
                    found
                })
                .collect();
            (hits, overlaps)
        })
        .unwrap()
}

/// The same questions asked of a fresh core index over the world's colliders.
fn fresh_answers(world: &mut World, rays: &[Ray], boxes: &[Isometry]) -> Answers {
    let colliders = world_colliders(world);
    let shapes: Vec<(Shape, Isometry)> =
        colliders.iter().map(|(_, s, p)| (s.clone(), *p)).collect();
    let mut index = indexed(&shapes);
    let mut all = Vec::new();
    let hits = rays
        .iter()
        .map(|r| {
            // The ray as `SpatialQuery` makes it from its origin and direction.
            let r = &Ray::new(r.origin(), r.direction()).unwrap();
            index
                .cast_ray_all(&*shapes, r, 60.0, |_| true, &mut all)
                .unwrap();
            all.iter()
                .map(|h| (colliders[h.id as usize].0, h.hit.distance))
                .collect()
        })
        .collect();
    let shape = Shape::cuboid(Vec3::new(2.0, 3.0, 1.5));
    let overlaps = boxes
        .iter()
        .map(|pose| {
            let mut ids = Vec::new();
            index.overlapping(&*shapes, (&shape, pose), |_| true, &mut ids);
            let mut found: Vec<Entity> = ids.iter().map(|&i| colliders[i as usize].0).collect();
            found.sort();
            found
        })
        .collect();
    (hits, overlaps)
}

/// Hits sorted by distance then entity: the index orders ties by its own ids.
fn canonical((mut hits, overlaps): Answers) -> Answers {
    for h in &mut hits {
        h.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    }
    (hits, overlaps)
}

fn random_static(rng: &mut Rng) -> (Collider, Position, Rotation, Static) {
    let collider = match rng.below(3) {
        0 => Collider::sphere(rng.range(0.3, 1.5)),
        1 => Collider::cuboid(
            rng.range(0.2, 2.0),
            rng.range(0.2, 2.0),
            rng.range(0.2, 2.0),
        ),
        _ => Collider::capsule(rng.range(0.0, 1.0), rng.range(0.2, 0.8)),
    };
    (
        collider,
        Position(rng.in_ball(20.0)),
        Rotation(rng.rotation()),
        Static,
    )
}

/// Steps `n` times, the answers to `rays` equal to a fresh index's after each; returns how
/// many times the still group was read in those steps.
fn quiet_steps(app: &mut App, rays: &[Ray], n: usize) -> u64 {
    ecs_answers(app, rays, &[], false);
    let reads = still_reads(app);
    for _ in 0..n {
        urto::step(app.world_mut(), 1).unwrap();
        let ours = canonical(ecs_answers(app, rays, &[], false));
        assert_eq!(ours, canonical(fresh_answers(app.world_mut(), rays, &[])));
    }
    still_reads(app) - reads
}

fn still_reads(app: &App) -> u64 {
    app.world()
        .resource::<SpatialQueryIndex>()
        .refreshes()
        .still_reads
}

fn sleeping_reads(app: &App) -> u64 {
    app.world()
        .resource::<SpatialQueryIndex>()
        .refreshes()
        .sleeping_reads
}

/// 300 statics, a wall and 60 balls flying in zero gravity; for 40 steps the game edits a few
/// statics each step (moves, turns, reshapes, despawns, spawns, quarantines and releases,
/// takes `Static` away or gives it), and the queries after each step (and after edits made
/// between steps and a [`SpatialQuery::refresh`]) equal a fresh index's over the world. Then
/// 30 quiet steps read the settled statics not once.
#[test]
fn settled_statics_edited_for_40_steps_answer_as_a_fresh_index_and_30_quiet_steps_read_them_0_times()
 {
    let mut app = common::app();
    let mut rng = Rng::new(43);
    let world = app.world_mut();
    let mut statics: Vec<Entity> = (0..300)
        .map(|_| world.spawn(random_static(&mut rng)).id())
        .collect();
    world.spawn((
        Collider::half_space(Vec3::new(1.0, 0.2, 0.0)),
        Position::new(-25.0, 0.0, 0.0),
        Static,
    ));
    for _ in 0..60 {
        world.spawn((
            Collider::sphere(0.4),
            Position(rng.in_ball(20.0)),
            Velocity(rng.in_ball(3.0)),
        ));
    }
    let mut quarantined: Vec<Entity> = Vec::new();
    for step in 0..40 {
        let world = app.world_mut();
        // The statics edited (or spawned) this step, each aimed at by a ray and a box below.
        let mut edited = Vec::new();
        for _ in 0..rng.below(4) {
            let e = statics[rng.below(statics.len())];
            edited.push(e);
            let mut entity = world.entity_mut(e);
            match rng.below(9) {
                0 => drop(entity.insert(Position(rng.in_ball(20.0)))),
                1 => drop(entity.insert(Rotation(rng.rotation()))),
                2 => drop(entity.insert(Collider::sphere(rng.range(0.5, 2.0)))),
                3 => {
                    entity.despawn();
                    statics.retain(|&s| s != e);
                }
                4 => {
                    entity.insert(Quarantined {
                        reason: "test".into(),
                    });
                    quarantined.push(e);
                }
                5 => drop(entity.remove::<Static>()),
                6 => drop(entity.insert(Static)),
                7 => drop(entity.remove::<Collider>()),
                _ => statics.push(world.spawn(random_static(&mut rng)).id()),
            }
        }
        if step % 3 == 0
            && let Some(e) = quarantined.pop()
            && let Ok(mut entity) = app.world_mut().get_entity_mut(e)
        {
            entity.remove::<Quarantined>();
            edited.push(e);
        }
        edited.extend(statics.last());
        urto::step(app.world_mut(), 1).unwrap();
        let mut rays: Vec<Ray> = (0..20).map(|_| random_ray(&mut rng)).collect();
        let mut boxes: Vec<Isometry> = (0..10)
            .map(|_| Isometry::new(rng.in_ball(20.0), rng.rotation()))
            .collect();
        for e in edited {
            if let Some(at) = app.world().get::<Position>(e).map(|p| p.0) {
                let from = at + rng.in_ball(1.0).normalize_or(Vec3::X) * 25.0;
                rays.push(Ray::new(from, at - from).unwrap());
                boxes.push(Isometry::new(at, rng.rotation()));
            }
        }
        let ours = canonical(ecs_answers(&mut app, &rays, &boxes, false));
        let fresh = canonical(fresh_answers(app.world_mut(), &rays, &boxes));
        assert_eq!(ours, fresh, "step {step}");
        // Moved between steps: seen after a refresh.
        let e = statics[rng.below(statics.len())];
        if let Ok(mut entity) = app.world_mut().get_entity_mut(e) {
            entity.insert(Position(rng.in_ball(20.0)));
        }
        let ours = canonical(ecs_answers(&mut app, &rays, &boxes, true));
        let fresh = canonical(fresh_answers(app.world_mut(), &rays, &boxes));
        assert_eq!(ours, fresh, "step {step}, refreshed");
    }
    urto::step(app.world_mut(), 2).unwrap();
    let rays: Vec<Ray> = (0..20).map(|_| random_ray(&mut rng)).collect();
    let reads = quiet_steps(&mut app, &rays, 30);
    assert_eq!(reads, 0, "quiet steps read no settled static");
    let refreshes = app.world().resource::<SpatialQueryIndex>().refreshes();
    assert!(refreshes.refits >= 30, "{refreshes:?}");
}

/// 120 balls dropped on a ground fall asleep (into the index's sleeping group): after every
/// step — while they sleep, while a few the game kicks wake, fly and fall asleep again, and for
/// one the game wakes between steps — the answers equal a fresh index's over the world; 30
/// quiet steps read the sleepers 0 times, and neither sleeping nor waking reads the settled
/// ground again.
#[test]
fn sleeping_balls_answer_as_a_fresh_index_through_waking_and_30_quiet_steps_read_them_0_times() {
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    let mut rng = Rng::new(48);
    let world = app.world_mut();
    world.spawn((Collider::half_space(Vec3::Z), Static));
    let balls: Vec<Entity> = (0..120)
        .map(|i| {
            let at = Vec3::new((i % 12) as f32 * 1.5, (i / 12) as f32 * 1.5, 0.6);
            world
                .spawn((
                    Collider::sphere(0.5),
                    Position(at),
                    Velocity::default(),
                    RollingResistance(0.02),
                ))
                .id()
        })
        .collect();
    urto::step(app.world_mut(), 240).unwrap();
    let asleep = |app: &App| {
        let world = app.world();
        balls
            .iter()
            .filter(|&&b| world.get::<Sleeping>(b).is_some())
            .count()
    };
    assert_eq!(asleep(&app), balls.len(), "all asleep");
    // Rays down onto the balls and through the rows.
    let rays: Vec<Ray> = (0..40)
        .map(|i| {
            let from = Vec3::new(rng.range(-1.0, 18.0), rng.range(-1.0, 16.0), 5.0);
            let to = if i % 2 == 0 {
                from - Vec3::Z
            } else {
                Vec3::new(rng.range(-1.0, 18.0), rng.range(-1.0, 16.0), 0.4)
            };
            Ray::new(from, to - from).unwrap()
        })
        .collect();
    ecs_answers(&mut app, &rays, &[], false);
    let sleepers_read = sleeping_reads(&app);
    assert_eq!(
        quiet_steps(&mut app, &rays, 30),
        0,
        "quiet steps read no static"
    );
    assert_eq!(sleeping_reads(&app), sleepers_read, "nor a sleeper");
    let reads = still_reads(&app);
    // Woken by game code between steps (the marker taken off): hit at once, where it sleeps.
    let woken = balls[5];
    app.world_mut().entity_mut(woken).remove::<Sleeping>();
    let at = app.world().get::<Position>(woken).unwrap().0;
    let down = [Ray::new(at + Vec3::new(0.1, 0.0, 5.0), -Vec3::Z).unwrap()];
    let ours = canonical(ecs_answers(&mut app, &down, &[], false));
    assert_eq!(ours.0[0].first().map(|h| h.0), Some(woken));
    assert_eq!(ours, canonical(fresh_answers(app.world_mut(), &down, &[])));
    let kicked: Vec<Entity> = balls.iter().step_by(17).copied().collect();
    for &b in &kicked {
        let kick = Velocity(Vec3::new(0.0, 0.5, 4.0));
        app.world_mut().entity_mut(b).insert(kick);
    }
    let mut woke = 0;
    for step in 0..600 {
        urto::step(app.world_mut(), 1).unwrap();
        woke = woke.max(balls.len() - asleep(&app));
        // The rays, and one down onto each kicked ball where it is now.
        let mut aimed = rays.clone();
        for &b in &kicked {
            let at = app.world().get::<Position>(b).unwrap().0;
            aimed.push(Ray::new(at + Vec3::new(0.1, 0.0, 5.0), -Vec3::Z).unwrap());
        }
        let ours = canonical(ecs_answers(&mut app, &aimed, &[], false));
        let fresh = canonical(fresh_answers(app.world_mut(), &aimed, &[]));
        assert_eq!(ours, fresh, "step {step} after the kicks");
        if step > 60 && asleep(&app) == balls.len() {
            break;
        }
    }
    assert!(woke >= kicked.len(), "{woke} woke");
    assert_eq!(asleep(&app), balls.len(), "all asleep again");
    assert_eq!(still_reads(&app), reads, "sleep and wakes read no static");
    // They read the sleepers again, at most once a step.
    let sleepers_read = sleeping_reads(&app) - sleepers_read;
    assert!((2..=601).contains(&sleepers_read), "{sleepers_read} reads");
}

//! The debug views the example games need, read back from the recording: the static grid's
//! cells and candidates of a moving body (checked against cells and boxes computed here from the
//! cell size alone), the scene graph's volumes level by level, and the nodes the narrow phase's
//! descent entered and pruned. All are off by default, and none changes a simulation result.
#![cfg(feature = "rerun")]

mod common;

use bevy_app::App;
use bevy_ecs::name::Name;
use bevy_ecs::prelude::*;
use glam::Vec3;
use rerun::ChunkStore;
use std::collections::BTreeSet;
use urto::bounding::Aabb;
use urto::debug::{RerunConfig, RerunDebugPlugin};
use urto::plugins::BroadPhaseIndex;
use urto::plugins::narrow_phase::HierarchyVisits;
use urto::prelude::*;

const STEPS: u32 = 30;

/// What the tests look at after the run.
struct Scene {
    car: Entity,
    buildings: Vec<Aabb>,
    /// The arm's nodes by depth: root, [upper, lower-far], [hand].
    arm: Vec<Vec<Entity>>,
    ball: Entity,
}

/// A block of buildings on both sides of the origin, a kinematic car (a chassis with two
/// wheels) driving along a row of them, its side overlapping theirs, and a static arm (root, two
/// links, a hand) with a ball coming to rest against the hand.
fn build_scene(app: &mut App) -> Scene {
    app.insert_resource(ContactSettings {
        default_restitution: 0.0,
        ..Default::default()
    });
    let world = app.world_mut();
    let mut buildings = Vec::new();
    for i in 0..6 {
        for j in 0..4 {
            let c = Vec3::new(-7.3 + 3.1 * i as f32, -6.7 + 4.3 * j as f32, 1.5);
            let half = Vec3::new(1.0, 1.2, 1.5);
            world.spawn((
                Collider::cuboid(half.x, half.y, half.z),
                Position(c),
                Static,
            ));
            buildings.push(Aabb::from_center_half_extents(c, half));
        }
    }
    let car = world
        .spawn((
            Collider::cuboid(0.9, 0.4, 0.3),
            Position::new(-6.0, 0.5, 0.8),
            Velocity::new(5.5, 0.0, 0.0),
            Mass::INFINITE,
        ))
        .id();
    for x in [-0.6, 0.6] {
        world.spawn((
            Collider::sphere(0.3),
            Position::new(x, 0.0, -0.4),
            ChildOf(car),
        ));
    }
    let arm = world
        .spawn((Position::new(0.0, 30.0, 0.0), Static, Name::new("base")))
        .id();
    let upper = world
        .spawn((
            Collider::cuboid(1.0, 0.2, 0.2),
            Position::new(1.0, 0.0, 0.5),
            ChildOf(arm),
            Name::new("upper"),
        ))
        .id();
    let far = world
        .spawn((
            Collider::cuboid(0.2, 0.2, 1.0),
            Position::new(-3.0, 0.0, 1.0),
            ChildOf(arm),
        ))
        .id();
    let hand = world
        .spawn((
            Collider::cuboid(0.2, 0.3, 0.2),
            Position::new(1.2, 0.0, 0.0),
            ChildOf(upper),
            Name::new("hand"),
        ))
        .id();
    let ball = world
        .spawn((
            Collider::sphere(0.3),
            Position::new(2.75, 30.0, 0.5),
            Velocity::new(-0.5, 0.0, 0.0),
        ))
        .id();
    Scene {
        car,
        buildings,
        arm: vec![vec![arm], vec![upper, far], vec![hand]],
        ball,
    }
}

fn all_views() -> RerunConfig {
    RerunConfig {
        grid_cells: true,
        scene_graph_levels: 3,
        hierarchy_visits: true,
        ..RerunConfig::file("unused.rrd")
    }
}

fn recorded(config: RerunConfig) -> (ChunkStore, App, Scene) {
    let (rec, storage) = rerun::RecordingStreamBuilder::new("urto_debug_views")
        .memory()
        .expect("memory sink");
    let mut app = common::app();
    app.add_plugins(RerunDebugPlugin::from_stream(rec.clone(), config));
    let scene = build_scene(&mut app);
    urto::step(app.world_mut(), STEPS).unwrap();
    let store = common::recording::read_back(&rec, &storage);
    (store, app, scene)
}

/// The boxes logged at `entity` on the last step, as AABBs (centre ± half size).
fn last_boxes(store: &ChunkStore, entity: &str) -> Vec<Aabb> {
    let centers = rerun::Boxes3D::descriptor_centers().component;
    let halves = rerun::Boxes3D::descriptor_half_sizes().component;
    let mut last: Option<(i64, Vec<Aabb>)> = None;
    for chunk in store.iter_physical_chunks() {
        if chunk.entity_path().to_string() != entity {
            continue;
        }
        let rows = chunk.iter_indices(&"step".into());
        let c = chunk.iter_component::<rerun::components::Translation3D>(centers);
        let h = chunk.iter_component::<rerun::components::HalfSize3D>(halves);
        for (((t, _), c), h) in rows.zip(c).zip(h) {
            let boxes = c
                .iter()
                .zip(h.iter())
                .map(|(c, h)| {
                    let (c, h) = (Vec3::from_array(c.0.into()), Vec3::from_array(h.0.into()));
                    Aabb::from_center_half_extents(c, h)
                })
                .collect();
            if last.as_ref().is_none_or(|(s, _)| t.as_i64() >= *s) {
                last = Some((t.as_i64(), boxes));
            }
        }
    }
    let (step, boxes) = last.unwrap_or_else(|| panic!("nothing logged at {entity}"));
    assert_eq!(step, i64::from(STEPS), "{entity} is logged every step");
    boxes
}

/// The labels logged at `entity` on its last row.
fn last_labels(store: &ChunkStore, entity: &str) -> Vec<String> {
    let labels = rerun::Boxes3D::descriptor_labels().component;
    let mut out = Vec::new();
    for chunk in store.iter_physical_chunks() {
        if chunk.entity_path().to_string() == entity {
            for batch in chunk.iter_component::<rerun::components::Text>(labels) {
                out = batch.iter().map(|t| t.as_str().to_owned()).collect();
            }
        }
    }
    out
}

fn entities(store: &ChunkStore) -> BTreeSet<String> {
    store.all_entities().iter().map(|e| e.to_string()).collect()
}

/// The cells of `b` as `(min, max)` integer corners, from the cell size alone.
fn cell_range(b: &Aabb, cell: Vec3) -> (glam::IVec3, glam::IVec3) {
    (
        (b.min / cell).floor().as_ivec3(),
        (b.max / cell).floor().as_ivec3(),
    )
}

fn close(a: &Aabb, b: &Aabb, tol: f32) -> bool {
    (a.min - b.min).abs().max_element() <= tol && (a.max - b.max).abs().max_element() <= tol
}

#[test]
fn the_grid_cells_and_candidates_are_those_of_the_moving_volumes() {
    let (store, app, scene) = recorded(all_views());
    let world = app.world();
    let cell = world.resource::<BroadPhaseIndex>().grid().cell_size();
    // Two moving bodies (the car, the ball); the statics are the buildings and the arm.
    let moving = [scene.car, scene.ball].map(|e| world.get::<BoundingVolume>(e).unwrap().0);
    let mut statics = scene.buildings.clone();
    statics.push(world.get::<BoundingVolume>(scene.arm[0][0]).unwrap().0);
    let mut expected_cells = Vec::new();
    for volume in &moving {
        let (lo, hi) = cell_range(volume, cell);
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    let min = glam::IVec3::new(x, y, z).as_vec3() * cell;
                    expected_cells.push(Aabb::new(min, min + cell));
                }
            }
        }
    }
    let mut logged = last_boxes(&store, "/broad_phase/grid_cells/occupied");
    logged.extend(last_boxes(&store, "/broad_phase/grid_cells/empty"));
    assert_eq!(
        logged.len(),
        expected_cells.len(),
        "one box per touched cell"
    );
    for c in &expected_cells {
        assert!(
            logged.iter().any(|l| close(l, c, 1e-3)),
            "cell {c:?} missing"
        );
    }

    // Candidates: every static sharing a cell with a moving body; red if its box meets one.
    let shares_cell = |b: &Aabb| {
        let (blo, bhi) = cell_range(b, cell);
        moving.iter().any(|m| {
            let (lo, hi) = cell_range(m, cell);
            blo.cmple(hi).all() && lo.cmple(bhi).all()
        })
    };
    let touches = |b: &Aabb| moving.iter().any(|m| m.intersects(b));
    let listed = last_boxes(&store, "/broad_phase/candidates/listed");
    let overlapping = last_boxes(&store, "/broad_phase/candidates/overlapping");
    let is_drawn = |set: &[Aabb], b: &Aabb| set.iter().any(|d| d.contains(b));
    let mut expected = (0, 0);
    for b in &statics {
        let (l, o) = (is_drawn(&listed, b), is_drawn(&overlapping, b));
        match (shares_cell(b), touches(b)) {
            (true, true) => assert!(o && !l, "{b:?} should be an overlapping candidate"),
            (true, false) => assert!(l && !o, "{b:?} should be a listed candidate"),
            (false, _) => assert!(!l && !o, "{b:?} shares no cell with a moving body"),
        }
        expected.0 += usize::from(shares_cell(b) && !touches(b));
        expected.1 += usize::from(shares_cell(b) && touches(b));
    }
    assert_eq!((listed.len(), overlapping.len()), expected);
    assert!(
        expected.0 > 0 && expected.1 > 1,
        "the car drives along buildings, touching some, and the ball touches the arm: {expected:?}"
    );
}

#[test]
fn the_scene_graph_levels_are_the_hierarchies_volumes_with_their_names() {
    let (store, app, scene) = recorded(all_views());
    let world = app.world();
    // Two hierarchies: the car (chassis, 2 wheels) and the arm (base, 2 links, a hand).
    let wheels: Vec<Entity> = world.get::<Children>(scene.car).unwrap().iter().collect();
    let depth_nodes = [
        vec![scene.car, scene.arm[0][0]],
        [wheels.clone(), scene.arm[1].clone()].concat(),
        scene.arm[2].clone(),
    ];
    for (k, nodes) in depth_nodes.iter().enumerate() {
        let logged = last_boxes(&store, &format!("/scene_graph/level_{k}"));
        assert_eq!(logged.len(), nodes.len(), "level {k}");
        for e in nodes {
            let bv = world.get::<BoundingVolume>(*e).unwrap().0;
            assert!(
                logged.iter().any(|l| close(l, &bv, 1e-4)),
                "level {k}: {e}'s volume {bv:?} missing from {logged:?}"
            );
        }
    }
    let mut names = last_labels(&store, "/scene_graph/level_1");
    names.sort();
    assert_eq!(names, ["", "", "", "upper"]);
    assert!(
        !entities(&store).contains("/scene_graph/level_3"),
        "3 levels asked"
    );
}

#[test]
fn the_descent_enters_the_near_branch_and_prunes_the_far_one() {
    let (store, app, scene) = recorded(all_views());
    let visits = app.world().resource::<HierarchyVisits>();
    let entered: Vec<Entity> = visits.entered.iter().map(|(e, _)| *e).collect();
    let pruned: Vec<Entity> = visits.pruned.iter().map(|(e, _)| *e).collect();
    let [root, upper, far, hand] = [
        scene.arm[0][0],
        scene.arm[1][0],
        scene.arm[1][1],
        scene.arm[2][0],
    ];
    for e in [root, upper, hand, scene.ball] {
        assert!(entered.contains(&e), "{e} entered: {visits:?}");
    }
    assert!(pruned.contains(&far), "the far link is pruned: {visits:?}");
    assert!(entered.windows(2).all(|w| w[0] < w[1]), "sorted, each once");
    assert!(
        visits.collider_pairs.contains(&(scene.ball, hand))
            || visits.collider_pairs.contains(&(hand, scene.ball)),
        "the ball and the hand go to the exact test: {visits:?}"
    );
    assert!(
        !visits
            .collider_pairs
            .iter()
            .any(|p| p.0 == far || p.1 == far),
        "nothing reaches the far link"
    );
    let logged_entered = last_boxes(&store, "/scene_graph/visited/entered");
    let logged_pruned = last_boxes(&store, "/scene_graph/visited/pruned");
    assert_eq!(logged_entered.len(), visits.entered.len());
    assert_eq!(logged_pruned.len(), visits.pruned.len());
    assert!(entities(&store).contains("/scene_graph/visited/collider_pairs"));
}

#[test]
fn the_views_are_off_by_default_and_change_no_result() {
    let (store, app, scene) = recorded(RerunConfig::file("unused.rrd"));
    let names = entities(&store);
    assert!(
        !names
            .iter()
            .any(|n| n.starts_with("/scene_graph") || n.starts_with("/broad_phase/grid_cells")),
        "{names:?}"
    );
    let visits = app.world().resource::<HierarchyVisits>();
    assert!(!visits.enabled && visits.entered.is_empty() && visits.pruned.is_empty());

    let positions =
        |app: &App, s: &Scene| [s.car, s.ball].map(|e| app.world().get::<Position>(e).unwrap().0);
    let mut plain = common::app();
    let plain_scene = build_scene(&mut plain);
    urto::step(plain.world_mut(), STEPS).unwrap();
    let (_, with_views, views_scene) = recorded(all_views());
    let expected = positions(&plain, &plain_scene);
    assert_eq!(positions(&with_views, &views_scene), expected);
    assert_eq!(positions(&app, &scene), expected);
}

/// A hinge swinging a ball of radius 0.1 m, 1 m from a pivot at (0, 0, 2), recorded to memory for
/// `STEPS` steps; `motor` drives it. Returns the recording, the app, the ball and the joint.
fn recorded_hinge(motor: Option<JointMotor>) -> (ChunkStore, App, Entity, Entity) {
    let (rec, storage) = rerun::RecordingStreamBuilder::new("urto_joint_views")
        .memory()
        .expect("memory sink");
    let mut app = common::app();
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.add_plugins(RerunDebugPlugin::from_stream(
        rec.clone(),
        RerunConfig::file("unused.rrd"),
    ));
    let bob = app
        .world_mut()
        .spawn((
            Collider::sphere(0.1),
            Position::new(1.0, 0.0, 2.0),
            Velocity::default(),
        ))
        .id();
    let mut joint = Joint::revolute(bob, JointEnd::World)
        .with_axis(Vec3::Y)
        .with_anchors(Vec3::new(-1.0, 0.0, 0.0), HINGE_PIVOT);
    if let Some(motor) = motor {
        joint = joint.with_motor(motor);
    }
    let hinge = app.world_mut().spawn(joint).id();
    urto::step(app.world_mut(), STEPS).unwrap();
    let store = common::recording::read_back(&rec, &storage);
    (store, app, bob, hinge)
}

/// Where [`recorded_hinge`]'s hinge is fixed to the world.
const HINGE_PIVOT: Vec3 = Vec3::new(0.0, 0.0, 2.0);

#[test]
fn joints_are_drawn_at_their_anchors_with_their_axes_loads_and_motor_torques() {
    let (store, app, bob, _) = recorded_hinge(Some(JointMotor::velocity(0.0, 0.5)));
    let pivot = HINGE_PIVOT;
    let names = entities(&store);
    for path in [
        "/world/joints/links",
        "/world/joints/anchors",
        "/world/joints/axes",
        "/joints/past_limit",
    ] {
        assert!(names.contains(path), "{path} missing from {names:?}");
    }
    for series in ["/force", "/torque", "/motor"] {
        assert!(
            names
                .iter()
                .any(|n| n.starts_with("/joints/") && n.ends_with(series)),
            "{series} missing from {names:?}"
        );
    }
    // The last anchors drawn: the bob's anchor where the bob is now, and the pivot.
    let positions = rerun::Points3D::descriptor_positions().component;
    let mut last = Vec::new();
    for chunk in store.iter_physical_chunks() {
        if chunk.entity_path().to_string() == "/world/joints/anchors" {
            for batch in chunk.iter_component::<rerun::components::Position3D>(positions) {
                last = batch.iter().map(|p| Vec3::from_array(p.0.into())).collect();
            }
        }
    }
    let p = app.world().get::<Position>(bob).unwrap().0;
    let r = app.world().get::<Rotation>(bob).unwrap().0;
    let bob_anchor = p + r * Vec3::new(-1.0, 0.0, 0.0);
    assert_eq!(last.len(), 2, "{last:?}");
    assert!(
        (last[0] - bob_anchor).length() < 1e-5,
        "{last:?} vs {bob_anchor}"
    );
    assert!((last[1] - pivot).length() < 1e-5, "{last:?}");
    assert!(
        (bob_anchor - pivot).length() < 0.01,
        "the hinge holds: {bob_anchor}"
    );
}

/// A joint without a motor plots what it holds but no `/motor` series (a flat zero would read
/// as a motor holding nothing).
#[test]
fn a_joint_without_a_motor_logs_its_loads_and_no_motor_series() {
    let (store, _, _, hinge) = recorded_hinge(None);
    let names = entities(&store);
    for series in ["force", "torque"] {
        let path = format!("/joints/{hinge}/{series}");
        assert!(names.contains(&path), "{path} missing from {names:?}");
    }
    assert!(
        !names.iter().any(|n| n.ends_with("/motor")),
        "a motor series for a joint without a motor: {names:?}"
    );
}

//! Shared support for the integration tests (and the BVH bench and example, which include it
//! by path): apps with urto's plugins, a seeded generator, test meshes, and a reference
//! triangle–triangle test. Each test uses a different subset.
#![allow(dead_code)]

pub mod meshes;
#[cfg(feature = "rerun")]
pub mod recording;
pub mod rng;
pub mod timing;
pub mod tri_tri_sat;

use bevy_app::App;
use glam::Vec3;
use urto::geometry::Isometry;
use urto::prelude::*;

/// A triangle mesh as two arrays, the shape every BVH function takes.
#[derive(Clone, Debug)]
pub struct Mesh {
    pub vertices: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    pub fn corners(&self, t: u32) -> [Vec3; 3] {
        self.triangles[t as usize].map(|i| self.vertices[i as usize])
    }

    /// The vertices carried by `pose`.
    pub fn transformed_vertices(&self, pose: &Isometry) -> Vec<Vec3> {
        self.vertices
            .iter()
            .map(|v| pose.transform_point(*v))
            .collect()
    }

    /// Radius of the ball about the origin holding the mesh.
    pub fn radius(&self) -> f32 {
        self.vertices.iter().fold(0.0, |r, v| r.max(v.length()))
    }

    /// The mesh moved so its vertices' bounding box is centred on the origin.
    pub fn centred(mut self) -> Self {
        let b = urto::bounding::Aabb::from_points(self.vertices.iter().copied());
        let c = b.center();
        for v in &mut self.vertices {
            *v -= c;
        }
        self
    }
}

/// The leaf test used by the BVH and by brute force alike: triangle `ta` of A (in A's frame)
/// against triangle `tb` of B, whose vertices were carried into A's frame beforehand.
pub fn leaf_test<'a>(
    a: &'a Mesh,
    b: &'a Mesh,
    b_vertices_in_a: &'a [Vec3],
) -> impl FnMut(u32, u32) -> bool + 'a {
    move |ta, tb| {
        let ta = a.corners(ta);
        let tb = b.triangles[tb as usize].map(|i| b_vertices_in_a[i as usize]);
        tri_tri_sat::triangles_intersect(&ta, &tb)
    }
}

/// The leaf test of the BVH measurements: triangle `tb` of B carried into A's frame by `pose` on
/// the fly (as a query does, so its cost is part of `Cs`), then the separating-axis test.
pub fn posed_leaf_test<'a>(
    a: &'a Mesh,
    b: &'a Mesh,
    pose: &Isometry,
) -> impl FnMut(u32, u32) -> bool + 'a {
    posed_leaf_test_with(a, b, pose, tri_tri_sat::triangles_intersect)
}

/// [`posed_leaf_test`] with another triangle–triangle test.
pub fn posed_leaf_test_with<'a>(
    a: &'a Mesh,
    b: &'a Mesh,
    pose: &Isometry,
    test: impl Fn(&[Vec3; 3], &[Vec3; 3]) -> bool + 'a,
) -> impl FnMut(u32, u32) -> bool + 'a {
    let r = pose.rotation_matrix();
    let t = pose.translation;
    move |ta, tb| {
        let ta = a.corners(ta);
        let tb = b.corners(tb).map(|v| r * v + t);
        test(&ta, &tb)
    }
}

/// `count` seeded placements of B near A (see [`rng::Rng::placement`]), the same for every
/// contender measured on the pair.
pub fn placements(a: &Mesh, b: &Mesh, count: usize, seed: u64) -> Vec<Isometry> {
    let mut rng = rng::Rng::new(seed);
    let reach = a.radius() + b.radius();
    (0..count).map(|_| rng.placement(reach)).collect()
}

/// Every intersecting pair, by testing all of them, sorted.
pub fn brute_force_pairs(a: &Mesh, b: &Mesh, b_vertices_in_a: &[Vec3]) -> Vec<[u32; 2]> {
    let mut test = leaf_test(a, b, b_vertices_in_a);
    let mut out = Vec::new();
    for ta in 0..a.triangles.len() as u32 {
        for tb in 0..b.triangles.len() as u32 {
            if test(ta, tb) {
                out.push([ta, tb]);
            }
        }
    }
    out
}

/// An app with every urto stage and the given step.
pub fn app_with(dt: f32, substeps: u32) -> App {
    let mut app = App::new();
    app.add_plugins(UrtoPlugins::with_timestep(
        PhysicsTimestep::new(dt, substeps).expect("valid test timestep"),
    ));
    app
}

/// A dynamic ball of radius 0.5 m (1 kg) at `at`, at rest.
pub fn ball(app: &mut App, at: Vec3) -> bevy_ecs::entity::Entity {
    app.world_mut()
        .spawn((Collider::sphere(0.5), Position(at), Velocity::default()))
        .id()
}

/// Removes `e`'s `BoundingVolume` and puts the same one back, as a game may between steps.
pub fn put_volume_back(app: &mut App, e: bevy_ecs::entity::Entity) {
    let volume = *app
        .world()
        .get::<BoundingVolume>(e)
        .expect("a body with a volume");
    app.world_mut()
        .entity_mut(e)
        .remove::<BoundingVolume>()
        .insert(volume);
}

/// A dynamic unit box (1 kg) centred `z` above the origin, at rest.
pub fn crate_box(app: &mut App, z: f32) -> bevy_ecs::entity::Entity {
    app.world_mut()
        .spawn((
            Collider::cuboid(0.5, 0.5, 0.5),
            Position::new(0.0, 0.0, z),
            Velocity::default(),
        ))
        .id()
}

/// `app` with Earth's gravity along -z and a static ground: the half-space z <= 0.
pub fn on_ground(mut app: App) -> App {
    app.insert_resource(Gravity::EARTH_Z_UP);
    app.world_mut()
        .spawn((Collider::half_space(Vec3::Z), Static));
    app
}

/// An app at 60 Hz, one substep.
pub fn app() -> App {
    app_with(1.0 / 60.0, 1)
}

/// An app at 60 Hz with the legacy pipeline (the selected integrator and the impulse response
/// in every substep) instead of the rigid-body solver: for the tests of the lecture's response.
pub fn legacy_app() -> App {
    legacy_app_with(1.0 / 60.0, 1)
}

/// [`legacy_app`] with the given step.
pub fn legacy_app_with(dt: f32, substeps: u32) -> App {
    use bevy_app::PluginGroup;
    let mut app = App::new();
    app.add_plugins(
        UrtoPlugins::with_timestep(
            PhysicsTimestep::new(dt, substeps).expect("valid test timestep"),
        )
        .build()
        .disable::<urto::plugins::SoftStepPlugin>(),
    );
    app
}

/// The thin bodies of the spinning-throw tests, all 1 m across: a plate 1 cm thick, a
/// capsule and a stick 2 cm thick.
pub fn thin_bodies() -> [Collider; 3] {
    [
        Collider::cuboid(0.5, 0.5, 0.005),
        Collider::capsule(0.5, 0.01),
        Collider::cuboid(0.5, 0.01, 0.01),
    ]
}

/// An app without gravity in which `shape` (density 500) flies along +x at `speed` from
/// about x = 3.6 (a random share of a step's travel back, up to 0.5 m off the axis) at a wall
/// 1 cm thick across x = 5 (restitution 0.5), turned at random and spinning at `spin` rad/s
/// about a random axis; the app and the body.
pub fn thrown_spinning(
    shape: &Collider,
    (speed, spin): (f32, f32),
    rng: &mut rng::Rng,
) -> (App, bevy_ecs::entity::Entity) {
    let mut app = app();
    app.insert_resource(Gravity::new(Vec3::ZERO).unwrap());
    app.world_mut().spawn((
        Collider::cuboid(0.005, 10.0, 10.0),
        Position::new(5.0, 0.0, 0.0),
        Static,
        Restitution(0.5),
    ));
    let start = Vec3::new(3.6 - speed / 60.0 * rng.unit(), rng.range(-0.5, 0.5), 0.0);
    let body = app
        .world_mut()
        .spawn((
            shape.clone(),
            Position(start),
            Rotation(rng.rotation()),
            Velocity(Vec3::X * speed),
            AngularVelocity(rng.direction() * spin),
            Density(500.0),
        ))
        .id();
    (app, body)
}

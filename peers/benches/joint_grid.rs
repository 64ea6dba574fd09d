//! Joint grid peer benchmark: urto's joints against rapier3d's impulse joints on Box2D's
//! `joint_grid` scene (issue 15's benchmark), in 3D.
//!
//! The scene: an `N × N` net of balls (radius 0.4, 1 kg, 1 m apart) hanging in the x–z plane,
//! each tied to its upper and left neighbours by a ball joint at the midpoint; the seven middle
//! balls of the top row are static, the rest falls and swings (Box2D's `joint_grid`: `N = 100`,
//! 10,000 bodies and 19,800 joints). Collisions between the balls are switched off in both
//! engines (Box2D's group index −1): urto by `CollisionLayers::NONE`-style layers, rapier by
//! `InteractionGroups::none()`; both still carry the colliders. dt = 1/60, gravity 9.81 m/s²
//! down Z. urto runs its defaults (4 substeps, 60 Hz joints, one relax pass over the joints,
//! sleeping on) and 3 and 2 substeps (nearer rapier's error), rapier its defaults
//! (TGS-soft, 4 iterations, sleeping on, single-threaded). One criterion iteration is the first
//! `STEPS` steps of a fresh net (the build is not timed).
//!
//! Quality, printed once per engine to stderr: the worst joint gap (distance between a joint's
//! two anchors, the constraint error) after `STEPS` steps, and how far the net's bottom middle
//! ball has fallen (the sag; both engines should agree on it).
//!
//! Run (from `peers/`): `cargo bench --bench joint_grid 2> joint_grid_sanity.txt`;
//! `PEERS_JOINT_GRID_N=40` for a smaller net.

use bevy_app::App;
use bevy_ecs::entity::Entity;
use criterion::{
    BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};
use glam::Vec3;
use rapier3d::prelude as rp;
use std::time::Duration;
use urto::prelude::*;

#[path = "common/fresh_runs.rs"]
mod fresh_runs;
use fresh_runs::timed;
#[path = "common/rapier_world.rs"]
mod rapier_world;
use rapier_world::{RapierWorld, rv};

const DT: f32 = 1.0 / 60.0;
const STEPS: u32 = 60;
const RADIUS: f32 = 0.4;
const TOP: f32 = 100.0;

fn side() -> usize {
    std::env::var("PEERS_JOINT_GRID_N")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100)
}

/// The net: ball `k * n + i` at column `k`, row `i` (row 0 on top); whether it is static; and
/// the joints `(a, b, anchor on a, anchor on b)`.
struct Net {
    n: usize,
    centers: Vec<Vec3>,
    fixed: Vec<bool>,
    joints: Vec<(usize, usize, Vec3, Vec3)>,
}

impl Net {
    fn new(n: usize) -> Self {
        let (mut centers, mut fixed, mut joints) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..n {
            for i in 0..n {
                let index = k * n + i;
                centers.push(Vec3::new(k as f32, 0.0, TOP - i as f32));
                fixed.push(i == 0 && k + 3 >= n / 2 && k <= n / 2 + 3);
                if i > 0 {
                    joints.push((
                        index - 1,
                        index,
                        Vec3::new(0.0, 0.0, -0.5),
                        Vec3::new(0.0, 0.0, 0.5),
                    ));
                }
                if k > 0 {
                    joints.push((
                        index - n,
                        index,
                        Vec3::new(0.5, 0.0, 0.0),
                        Vec3::new(-0.5, 0.0, 0.0),
                    ));
                }
            }
        }
        Self {
            n,
            centers,
            fixed,
            joints,
        }
    }

    /// The worst joint gap and the bottom middle ball's drop, from the balls' poses.
    fn quality(&self, poses: &[(Vec3, glam::Quat)]) -> (f32, f32) {
        let gap = self
            .joints
            .iter()
            .map(|&(a, b, ra, rb)| {
                let (pa, qa) = poses[a];
                let (pb, qb) = poses[b];
                (pa + qa * ra).distance(pb + qb * rb)
            })
            .fold(0.0f32, f32::max);
        let bottom = (self.n / 2) * self.n + self.n - 1;
        (gap, self.centers[bottom].z - poses[bottom].0.z)
    }
}

struct Urto {
    app: App,
    balls: Vec<Entity>,
}

/// urto's defaults (4 substeps; joints relax once a substep, contacts twice), and with 3 and
/// 2 substeps (nearer rapier's joint gap, for a comparison at equal error): `(label,
/// substeps, contact relax passes)`; the relax passes over the joints are the default, one.
const URTO_VARIANTS: [(&str, u32, u32); 3] = [
    ("urto", 4, 2),
    ("urto (3 substeps)", 3, 2),
    ("urto (2 substeps)", 2, 1),
];

impl Urto {
    fn new(net: &Net, substeps: u32, relax_iterations: u32) -> Self {
        let settings = urto::dynamics::solver::SoftStepSettings {
            substeps,
            relax_iterations,
            ..Default::default()
        };
        let mut app = App::new();
        app.add_plugins(UrtoPlugins::default().set(SoftStepPlugin { settings }))
            .insert_resource(Gravity::new(Vec3::new(0.0, 0.0, -9.81)).expect("finite"));
        let alone = CollisionLayers::new(LayerMask::NONE, LayerMask::NONE);
        let world = app.world_mut();
        let balls: Vec<Entity> = net
            .centers
            .iter()
            .zip(&net.fixed)
            .map(|(&p, &fixed)| {
                let mut e = world.spawn((Collider::sphere(RADIUS), Position(p), alone));
                if fixed {
                    e.insert(Static);
                } else {
                    e.insert((Velocity::default(), Mass(1.0)));
                }
                e.id()
            })
            .collect();
        for &(a, b, ra, rb) in &net.joints {
            world.spawn(Joint::spherical(balls[a], balls[b]).with_anchors(ra, rb));
        }
        Self { app, balls }
    }

    fn step(&mut self, n: u32) {
        urto::step(self.app.world_mut(), n).expect("UrtoPlugins");
    }

    fn poses(&self) -> Vec<(Vec3, glam::Quat)> {
        let w = self.app.world();
        self.balls
            .iter()
            .map(|&b| {
                let p = w.get::<Position>(b).expect("ball").0;
                let r = w.get::<Rotation>(b).map_or(glam::Quat::IDENTITY, |r| r.0);
                (p, r)
            })
            .collect()
    }
}

struct Rapier {
    world: RapierWorld,
    balls: Vec<rp::RigidBodyHandle>,
}

impl Rapier {
    fn new(net: &Net) -> Self {
        let mut world = RapierWorld::new(rv(Vec3::new(0.0, 0.0, -9.81)), DT);
        let balls: Vec<rp::RigidBodyHandle> = net
            .centers
            .iter()
            .zip(&net.fixed)
            .map(|(&p, &fixed)| {
                let body = if fixed {
                    rp::RigidBodyBuilder::fixed()
                } else {
                    rp::RigidBodyBuilder::dynamic()
                };
                let c = rp::ColliderBuilder::ball(RADIUS)
                    .mass(1.0)
                    .collision_groups(rp::InteractionGroups::none());
                world.add(body.translation(rv(p)), c)
            })
            .collect();
        for &(a, b, ra, rb) in &net.joints {
            let joint = rp::SphericalJointBuilder::new()
                .local_anchor1(rv(ra))
                .local_anchor2(rv(rb));
            world.impulse_joints.insert(balls[a], balls[b], joint, true);
        }
        Self { world, balls }
    }

    fn step(&mut self, n: u32) {
        self.world.step(n);
    }

    fn poses(&self) -> Vec<(Vec3, glam::Quat)> {
        self.world.poses(&self.balls)
    }
}

fn bench_joint_grid(c: &mut Criterion) {
    let n = side();
    let net = Net::new(n);
    let bodies = net.centers.len();
    for (label, substeps, relax) in URTO_VARIANTS {
        let mut u = Urto::new(&net, substeps, relax);
        u.step(STEPS);
        let (gap, sag) = net.quality(&u.poses());
        let joints = u
            .app
            .world()
            .resource::<PhysicsStats>()
            .counter("soft_step/joints")
            .unwrap_or(0.0);
        eprintln!(
            "[sanity] joint grid {n}x{n} ({bodies} balls, {} joints) {label} after {STEPS} steps: worst joint gap {:.2} mm, bottom sag {:.3} m, joints solved {joints}",
            net.joints.len(),
            gap * 1e3,
            sag
        );
    }
    let mut r = Rapier::new(&net);
    r.step(STEPS);
    let (gap, sag) = net.quality(&r.poses());
    eprintln!(
        "[sanity] joint grid {n}x{n} rapier after {STEPS} steps: worst joint gap {:.2} mm, bottom sag {:.3} m",
        gap * 1e3,
        sag
    );

    let mut group = c.benchmark_group(format!("joint_grid_{n}x{n}_{STEPS}_steps"));
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .measurement_time(Duration::from_secs(10))
        .throughput(Throughput::Elements(u64::from(STEPS)));
    for (label, substeps, relax) in URTO_VARIANTS {
        group.bench_function(BenchmarkId::new(label, bodies), |b| {
            b.iter_custom(|iters| {
                timed(
                    iters,
                    || Urto::new(&net, substeps, relax),
                    |u| u.step(STEPS),
                )
            })
        });
    }
    group.bench_function(BenchmarkId::new("rapier", bodies), |b| {
        b.iter_custom(|iters| timed(iters, || Rapier::new(&net), |r| r.step(STEPS)))
    });
    group.finish();
}

criterion_group!(benches, bench_joint_grid);
criterion_main!(benches);

//! Ragdoll pile peer benchmark: urto's joints and capsules against rapier3d's impulse joints and
//! capsules, on the ragdoll pile of issue 15 (the scene Jolt's and Box2D's samples drop).
//!
//! The scene: `LAYERS` layers of `SIDE × SIDE` ragdolls lying on their backs, each layer turned
//! 90° from the one below, dropped together onto a ground (a half-space in urto, a large box in
//! rapier). A ragdoll is the `joints` example's: a capsule torso, a ball head, capsule upper and
//! lower arms and legs (10 bodies), ball joints at the neck, shoulders and hips with swing and
//! twist limits, limited hinges at the elbows and knees (9 joints). Jointed bodies do not
//! collide (both engines). Friction 0.6, no restitution, dt = 1/60, gravity 9.81 m/s² down Z.
//! urto runs its defaults (4 substeps, sleeping on); rapier its defaults (TGS-soft, 4
//! iterations, sleeping on, single-threaded), rotations unlocked. rapier bounds a ball joint's
//! swing per axis (a square cone) where urto bounds it by a round cone of the same half-angle.
//! One criterion iteration is the first `STEPS` steps of a fresh pile (the build is not timed).
//!
//! Quality, printed once per engine to stderr after `STEPS` steps: the worst joint gap (distance
//! between a joint's two anchors), the deepest body below the ground, and the pile's height.
//!
//! Run (from `peers/`): `cargo bench --bench ragdoll_pile 2> ragdoll_pile_sanity.txt`;
//! `PEERS_RAGDOLL_SIDE=2` for a smaller pile.

use bevy_app::App;
use bevy_ecs::entity::Entity;
use criterion::{
    BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};
use glam::{Quat, Vec3};
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
const STEPS: u32 = 180;
const LAYERS: usize = 3;
const FRICTION: f32 = 0.6;

fn side() -> usize {
    std::env::var("PEERS_RAGDOLL_SIDE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4)
}

/// A body: a capsule along its local z (`half_length`, `radius`) or a ball (`half_length` 0 and
/// `ball`), its centre and orientation, its mass.
#[derive(Clone, Copy)]
struct Part {
    ball: bool,
    half_length: f32,
    radius: f32,
    center: Vec3,
    orientation: Quat,
    mass: f32,
}

/// A joint between parts `a` and `b`: anchors in their frames, an axis (the same in both
/// frames), and its limits.
#[derive(Clone, Copy)]
struct Link {
    a: usize,
    b: usize,
    anchor_a: Vec3,
    anchor_b: Vec3,
    axis: Vec3,
    kind: LinkKind,
}

#[derive(Clone, Copy)]
enum LinkKind {
    /// Swing cone half-angle, twist bounds.
    Ball { swing: f32, twist: [f32; 2] },
    /// Hinge angle bounds.
    Hinge { limits: [f32; 2] },
}

/// Every ragdoll of the pile, as parts and links (indices into the pile's parts).
struct Pile {
    parts: Vec<Part>,
    links: Vec<Link>,
}

impl Pile {
    fn new(side: usize) -> Self {
        let mut pile = Pile {
            parts: Vec::new(),
            links: Vec::new(),
        };
        for layer in 0..LAYERS {
            // On its back (standing z turned onto x), each layer turned 90° about z.
            let lying = Quat::from_rotation_z(layer as f32 * std::f32::consts::FRAC_PI_2)
                * Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
            for i in 0..side {
                for j in 0..side {
                    let (u, v) = (i as f32 - 0.5 * side as f32, j as f32 - 0.5 * side as f32);
                    let across = if layer % 2 == 0 {
                        Vec3::new(2.0 * u, 0.9 * v, 0.0)
                    } else {
                        Vec3::new(0.9 * v, 2.0 * u, 0.0)
                    };
                    let at = across + Vec3::new(0.0, 0.0, 0.5 + 0.6 * layer as f32);
                    pile.add_ragdoll(at, lying);
                }
            }
        }
        pile
    }

    /// The `joints` example's ragdoll, its pelvis-height origin at `at`, turned by `turn`.
    fn add_ragdoll(&mut self, at: Vec3, turn: Quat) {
        let first = self.parts.len();
        let mut part = |ball: bool, half: f32, radius: f32, local: Vec3, mass: f32| {
            let half_length = if ball { 0.0 } else { half - radius };
            self.parts.push(Part {
                ball,
                half_length,
                radius,
                center: at + turn * (local - Vec3::new(0.0, 0.0, 0.8)),
                orientation: turn,
                mass,
            });
            self.parts.len() - 1
        };
        let torso = part(false, 0.25, 0.15, Vec3::new(0.0, 0.0, 1.05), 15.0);
        let head = part(true, 0.11, 0.11, Vec3::new(0.0, 0.0, 1.45), 4.0);
        let mut limbs = Vec::new();
        for side in [-1.0f32, 1.0] {
            let upper_arm = part(false, 0.15, 0.05, Vec3::new(0.0, side * 0.25, 1.13), 2.0);
            let forearm = part(false, 0.14, 0.045, Vec3::new(0.0, side * 0.25, 0.83), 1.5);
            let thigh = part(false, 0.2, 0.07, Vec3::new(0.0, side * 0.1, 0.6), 6.0);
            let shin = part(false, 0.19, 0.06, Vec3::new(0.0, side * 0.1, 0.19), 4.0);
            limbs.push((side, upper_arm, forearm, thigh, shin));
        }
        debug_assert_eq!(torso, first);
        let ball = |a, b, anchor_a, anchor_b, axis, swing, twist: f32| Link {
            a,
            b,
            anchor_a,
            anchor_b,
            axis,
            kind: LinkKind::Ball {
                swing,
                twist: [-twist, twist],
            },
        };
        let hinge = |a, b, anchor_a, anchor_b, limits| Link {
            a,
            b,
            anchor_a,
            anchor_b,
            axis: Vec3::Y,
            kind: LinkKind::Hinge { limits },
        };
        let (up, down) = (Vec3::Z, Vec3::NEG_Z);
        self.links.push(ball(
            torso,
            head,
            Vec3::new(0.0, 0.0, 0.27),
            Vec3::new(0.0, 0.0, -0.13),
            up,
            0.6,
            0.6,
        ));
        for (side, upper_arm, forearm, thigh, shin) in limbs {
            let z = |h: f32| Vec3::new(0.0, 0.0, h);
            self.links.extend([
                ball(
                    torso,
                    upper_arm,
                    Vec3::new(0.0, side * 0.25, 0.23),
                    z(0.15),
                    down,
                    1.5,
                    0.8,
                ),
                hinge(upper_arm, forearm, z(-0.16), z(0.15), [-2.4, 0.0]),
                ball(
                    torso,
                    thigh,
                    Vec3::new(0.0, side * 0.1, -0.26),
                    z(0.2),
                    down,
                    1.2,
                    0.5,
                ),
                hinge(thigh, shin, z(-0.205), z(0.195), [0.0, 2.4]),
            ]);
        }
    }

    /// The worst joint gap, the deepest point below z = 0 and the highest point of the pile.
    fn quality(&self, poses: &[(Vec3, Quat)]) -> (f32, f32, f32) {
        let gap = self
            .links
            .iter()
            .map(|l| {
                let (pa, qa) = poses[l.a];
                let (pb, qb) = poses[l.b];
                (pa + qa * l.anchor_a).distance(pb + qb * l.anchor_b)
            })
            .fold(0.0f32, f32::max);
        let (mut lowest, mut highest) = (f32::INFINITY, f32::NEG_INFINITY);
        for (part, &(p, q)) in self.parts.iter().zip(poses) {
            let reach = (q * Vec3::Z).z.abs() * part.half_length + part.radius;
            lowest = lowest.min(p.z - reach);
            highest = highest.max(p.z + reach);
        }
        (gap, (-lowest).max(0.0), highest)
    }
}

struct Urto {
    app: App,
    bodies: Vec<Entity>,
}

impl Urto {
    fn new(pile: &Pile) -> Self {
        let mut app = App::new();
        app.add_plugins(UrtoPlugins::default())
            .insert_resource(Gravity::new(Vec3::new(0.0, 0.0, -9.81)).expect("finite"));
        let world = app.world_mut();
        world.spawn((Collider::half_space(Vec3::Z), Static, Friction(FRICTION)));
        let bodies: Vec<Entity> = pile
            .parts
            .iter()
            .map(|p| {
                let collider = if p.ball {
                    Collider::sphere(p.radius)
                } else {
                    Collider::capsule(p.half_length, p.radius)
                };
                world
                    .spawn((
                        collider,
                        Position(p.center),
                        Rotation(p.orientation),
                        Velocity::default(),
                        Mass(p.mass),
                        Friction(FRICTION),
                    ))
                    .id()
            })
            .collect();
        for l in &pile.links {
            let (a, b) = (bodies[l.a], bodies[l.b]);
            let joint = match l.kind {
                LinkKind::Ball { swing, twist } => Joint::spherical(a, b)
                    .with_swing_limit(swing)
                    .with_limits(twist[0], twist[1]),
                LinkKind::Hinge { limits } => {
                    Joint::revolute(a, b).with_limits(limits[0], limits[1])
                }
            };
            world.spawn(joint.with_axis(l.axis).with_anchors(l.anchor_a, l.anchor_b));
        }
        Self { app, bodies }
    }

    fn step(&mut self, n: u32) {
        urto::step(self.app.world_mut(), n).expect("UrtoPlugins");
    }

    fn poses(&self) -> Vec<(Vec3, Quat)> {
        let w = self.app.world();
        self.bodies
            .iter()
            .map(|&b| {
                let p = w.get::<Position>(b).expect("part").0;
                let r = w.get::<Rotation>(b).map_or(Quat::IDENTITY, |r| r.0);
                (p, r)
            })
            .collect()
    }
}

struct Rapier {
    world: RapierWorld,
    bodies: Vec<rp::RigidBodyHandle>,
}

/// A joint frame for rapier: the anchor, and the rotation taking rapier's joint x axis to `axis`.
fn frame(anchor: Vec3, axis: Vec3) -> rp::Pose {
    let q = Quat::from_rotation_arc(Vec3::X, axis);
    rp::Pose::from_parts(rv(anchor), rp::Rotation::from_array(q.to_array()))
}

impl Rapier {
    fn new(pile: &Pile) -> Self {
        let mut world = RapierWorld::new(rv(Vec3::new(0.0, 0.0, -9.81)), DT);
        let ground = rp::ColliderBuilder::cuboid(200.0, 200.0, 1.0).friction(FRICTION);
        world.add(
            rp::RigidBodyBuilder::fixed().translation(rv(Vec3::NEG_Z)),
            ground,
        );
        let bodies: Vec<rp::RigidBodyHandle> = pile
            .parts
            .iter()
            .map(|p| {
                let shape = if p.ball {
                    rp::ColliderBuilder::ball(p.radius)
                } else {
                    rp::ColliderBuilder::capsule_z(p.half_length, p.radius)
                };
                let q = rp::Rotation::from_array(p.orientation.to_array());
                let body =
                    rp::RigidBodyBuilder::dynamic().pose(rp::Pose::from_parts(rv(p.center), q));
                world.add(body, shape.mass(p.mass).friction(FRICTION))
            })
            .collect();
        for l in &pile.links {
            let (fa, fb) = (frame(l.anchor_a, l.axis), frame(l.anchor_b, l.axis));
            let joint: rp::GenericJoint = match l.kind {
                LinkKind::Ball { swing, twist } => rp::SphericalJointBuilder::new()
                    .local_frame1(fa)
                    .local_frame2(fb)
                    .limits(rp::JointAxis::AngX, twist)
                    .limits(rp::JointAxis::AngY, [-swing, swing])
                    .limits(rp::JointAxis::AngZ, [-swing, swing])
                    .contacts_enabled(false)
                    .build()
                    .into(),
                LinkKind::Hinge { limits } => rp::RevoluteJointBuilder::new(rv(l.axis))
                    .local_anchor1(rv(l.anchor_a))
                    .local_anchor2(rv(l.anchor_b))
                    .limits(limits)
                    .contacts_enabled(false)
                    .build()
                    .into(),
            };
            world
                .impulse_joints
                .insert(bodies[l.a], bodies[l.b], joint, true);
        }
        Self { world, bodies }
    }

    fn step(&mut self, n: u32) {
        self.world.step(n);
    }

    fn poses(&self) -> Vec<(Vec3, Quat)> {
        self.world.poses(&self.bodies)
    }
}

fn bench_ragdoll_pile(c: &mut Criterion) {
    let side = side();
    let pile = Pile::new(side);
    let (bodies, joints) = (pile.parts.len(), pile.links.len());
    let report = |label: &str, poses: &[(Vec3, Quat)]| {
        let (gap, below, top) = pile.quality(poses);
        eprintln!(
            "[sanity] ragdoll pile {} ragdolls ({bodies} bodies, {joints} joints) {label} after {STEPS} steps: worst joint gap {:.2} mm, deepest below the ground {:.2} mm, pile {:.2} m high",
            bodies / 10,
            gap * 1e3,
            below * 1e3,
            top
        );
    };
    let mut u = Urto::new(&pile);
    u.step(STEPS);
    report("urto", &u.poses());
    let mut r = Rapier::new(&pile);
    r.step(STEPS);
    report("rapier", &r.poses());

    let mut group = c.benchmark_group(format!("ragdoll_pile_{}_{STEPS}_steps", bodies / 10));
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .measurement_time(Duration::from_secs(10))
        .throughput(Throughput::Elements(u64::from(STEPS)));
    group.bench_function(BenchmarkId::new("urto", bodies), |b| {
        b.iter_custom(|iters| timed(iters, || Urto::new(&pile), |u| u.step(STEPS)))
    });
    group.bench_function(BenchmarkId::new("rapier", bodies), |b| {
        b.iter_custom(|iters| timed(iters, || Rapier::new(&pile), |r| r.step(STEPS)))
    });
    group.finish();
}

criterion_group!(benches, bench_ragdoll_pile);
criterion_main!(benches);

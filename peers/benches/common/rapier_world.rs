//! The rapier3d world the peer benches step: its sets and pipeline, default integration
//! parameters at a given dt, single-threaded. Included by each bench with `#[path]`.

use rapier3d::prelude as rp;

/// A glam vector as rapier's.
pub fn rv(v: glam::Vec3) -> rp::Vector {
    rp::Vector::new(v.x, v.y, v.z)
}

/// Everything `PhysicsPipeline::step` takes.
pub struct RapierWorld {
    pub gravity: rp::Vector,
    pub params: rp::IntegrationParameters,
    pub pipeline: rp::PhysicsPipeline,
    pub islands: rp::IslandManager,
    pub broad_phase: rp::DefaultBroadPhase,
    pub narrow_phase: rp::NarrowPhase,
    pub bodies: rp::RigidBodySet,
    pub colliders: rp::ColliderSet,
    pub impulse_joints: rp::ImpulseJointSet,
    pub multibody_joints: rp::MultibodyJointSet,
    pub soft_bodies: rp::SoftBodySet,
    pub ccd: rp::CCDSolver,
}

impl RapierWorld {
    /// An empty world with rapier's default parameters but `dt`.
    pub fn new(gravity: rp::Vector, dt: f32) -> Self {
        Self {
            gravity,
            params: rp::IntegrationParameters {
                dt,
                ..Default::default()
            },
            pipeline: rp::PhysicsPipeline::new(),
            islands: rp::IslandManager::new(),
            broad_phase: rp::DefaultBroadPhase::default(),
            narrow_phase: rp::NarrowPhase::new(),
            bodies: rp::RigidBodySet::new(),
            colliders: rp::ColliderSet::new(),
            impulse_joints: rp::ImpulseJointSet::new(),
            multibody_joints: rp::MultibodyJointSet::new(),
            soft_bodies: rp::SoftBodySet::new(),
            ccd: rp::CCDSolver::new(),
        }
    }

    /// Adds a body with one collider; returns the body's handle.
    pub fn add(
        &mut self,
        body: rp::RigidBodyBuilder,
        collider: rp::ColliderBuilder,
    ) -> rp::RigidBodyHandle {
        let h = self.bodies.insert(body);
        self.colliders
            .insert_with_parent(collider, h, &mut self.bodies);
        h
    }

    /// The poses of `bodies`, as glam values (`whole_step` reads its own).
    #[allow(dead_code)]
    pub fn poses(&self, bodies: &[rp::RigidBodyHandle]) -> Vec<(glam::Vec3, glam::Quat)> {
        bodies
            .iter()
            .map(|h| {
                let body = &self.bodies[*h];
                let (t, q) = (body.translation(), body.rotation());
                (
                    glam::Vec3::new(t.x, t.y, t.z),
                    glam::Quat::from_xyzw(q.x, q.y, q.z, q.w),
                )
            })
            .collect()
    }

    /// `n` steps.
    pub fn step(&mut self, n: u32) {
        for _ in 0..n {
            self.pipeline.step(
                self.gravity,
                &self.params,
                &mut self.islands,
                &mut self.broad_phase,
                &mut self.narrow_phase,
                &mut self.bodies,
                &mut self.colliders,
                &mut self.impulse_joints,
                &mut self.multibody_joints,
                &mut self.soft_bodies,
                &mut self.ccd,
                &(),
                &(),
            );
        }
    }
}

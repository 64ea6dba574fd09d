//! Contact constraints with lever arms: one row along the normal and two friction rows per
//! point, solved softly (Box2D v3's `contact_solver.c`, in 3D; the Jacobians as in Avian's
//! `contact/normal_part.rs` and Jolt's `AxisConstraintPart`).
//!
//! # The normal row
//! For a point with anchors `r_a`, `r_b` (from each centre of mass) and normal `n` (A to B),
//! the separation is `C = (x_b + r_b − x_a − r_a)·n` and its rate
//!
//! `Ċ = (v_b + ω_b × r_b − v_a − ω_a × r_a)·n = J V`,
//! `J = [−nᵀ, −(r_a × n)ᵀ, nᵀ, (r_b × n)ᵀ]`,
//!
//! using `(ω × r)·n = ω·(r × n)`. The effective mass is `1/K` with
//! `K = J M⁻¹ Jᵀ = 1/m_a + 1/m_b + (r_a × n)·I_a⁻¹(r_a × n) + (r_b × n)·I_b⁻¹(r_b × n)`,
//! and an impulse `λ` changes the velocities by `M⁻¹ Jᵀ λ`: `v_a −= λn/m_a`,
//! `ω_a −= I_a⁻¹ (r_a × λn)`, and the opposite for B.
//!
//! # Separation during substeps
//! Contacts are found once per step. Within it each body has moved by `dp` and turned by `dq`
//! since the start, so the separation is updated without new detection (Box2D v3):
//! `s = s₀ + (dp_b − dp_a + dq_b r_b − dq_a r_a − (r_b − r_a))·n`; `s₀ − (r_b − r_a)·n` is kept
//! as the point's base separation.
//!
//! # Speculative and soft
//! A point still apart (`s > 0`) may close exactly its gap this substep (bias `s/h`): contacts
//! found before they touch stop bodies at the surface without bouncing or tunnelling. A point
//! in penetration is pushed out softly ([`Softness`]) at no more than `max_push_out`. The relax
//! pass solves again without bias, removing the velocity the push-out added, and friction
//! (Coulomb, both tangent rows clamped together to the disc `μ λ_n`) is solved in the relax
//! pass only, as Box2D does: friction in the biased pass fights the push-out and lets stacks
//! creep.

use super::body::{BodyParams, BodyState};
use super::softness::Softness;
use crate::geometry::MAX_MANIFOLD_POINTS;
use glam::Vec3;

/// One point of a contact as detection found it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactPointInput {
    /// World point (between the surfaces).
    pub point: Vec3,
    /// Distance between the surfaces along the normal: negative in penetration.
    pub separation: f32,
}

/// A contact between two bodies (slots into [`SolverBodies`](super::SolverBodies)), with up to
/// [`MAX_MANIFOLD_POINTS`] points sharing a normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactInput {
    /// First body's slot.
    pub a: u32,
    /// Second body's slot.
    pub b: u32,
    /// Unit normal from A to B.
    pub normal: Vec3,
    /// Coulomb friction coefficient of the pair.
    pub friction: f32,
    /// Coefficient of restitution of the pair.
    pub restitution: f32,
    /// The points (the first `count`).
    pub points: [ContactPointInput; MAX_MANIFOLD_POINTS],
    /// How many points are used.
    pub count: u8,
    /// A key stable from step to step for the same pair of colliders (warm starting follows
    /// it); contacts must be given in increasing key order.
    pub key: u64,
}

/// A point of a prepared constraint.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ConstraintPoint {
    /// Anchor from A's centre of mass (world axes at the step's start).
    pub anchor_a: Vec3,
    /// Anchor from B's centre of mass.
    pub anchor_b: Vec3,
    /// `s₀ − (r_b − r_a)·n` (see the module doc).
    pub base_separation: f32,
    /// `1/K` of the normal row.
    pub normal_mass: f32,
    /// `1/K` of each friction row.
    pub tangent_mass: [f32; 2],
    /// Accumulated normal impulse of the current substep (N·s).
    pub normal_impulse: f32,
    /// Accumulated friction impulses along the two tangents.
    pub tangent_impulse: [f32; 2],
    /// Largest normal impulse of the step, warm start included (restitution skips points that
    /// never pushed).
    pub max_normal_impulse: f32,
    /// Normal relative velocity when the point began to push (at the step's start for a point
    /// already pushing): the approach speed restitution reverses. Taken at the substep of
    /// impact, not the step's start, so a bounce does not lose the speed gravity added during
    /// the step before it.
    pub relative_velocity: f32,
}

/// A prepared contact: its rows and accumulated impulses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactConstraint {
    /// First body's slot.
    pub a: u32,
    /// Second body's slot.
    pub b: u32,
    /// Unit normal from A to B.
    pub normal: Vec3,
    /// Orthonormal tangents spanning the friction plane.
    pub tangents: [Vec3; 2],
    /// Coulomb coefficient.
    pub friction: f32,
    /// Restitution coefficient.
    pub restitution: f32,
    /// Softness of the push-out (stiffer against immovable bodies).
    pub softness: Softness,
    /// The points.
    pub points: [ConstraintPoint; MAX_MANIFOLD_POINTS],
    /// How many are used.
    pub count: u8,
    /// The caller's pair key.
    pub key: u64,
    /// Solve the points backwards this substep (flipped every substep).
    pub flip: bool,
}

/// `r × n` and `K = 1/m_a + 1/m_b + (r_a×n)·I_a⁻¹(r_a×n) + (r_b×n)·I_b⁻¹(r_b×n)`, inverted.
fn effective_mass(pa: &BodyParams, pb: &BodyParams, ra: Vec3, rb: Vec3, dir: Vec3) -> f32 {
    let (rna, rnb) = (ra.cross(dir), rb.cross(dir));
    let k = pa.inverse_mass
        + pb.inverse_mass
        + rna.dot(pa.inverse_inertia * rna)
        + rnb.dot(pb.inverse_inertia * rnb);
    if k > 0.0 && k.is_finite() {
        1.0 / k
    } else {
        0.0
    }
}

/// Velocity of the point at `r` of a body.
fn point_velocity(s: &BodyState, r: Vec3) -> Vec3 {
    s.linear_velocity + s.angular_velocity.cross(r)
}

impl ContactConstraint {
    /// Builds the rows from detection data at the step's start (`centers`: centres of mass).
    pub fn prepare(
        input: &ContactInput,
        centers: &[Vec3],
        states: &[BodyState],
        params: &[BodyParams],
        softness: Softness,
    ) -> Self {
        let (ia, ib) = (input.a as usize, input.b as usize);
        let (pa, pb) = (&params[ia], &params[ib]);
        let n = input.normal;
        let tangents = {
            let (t1, t2) = n.any_orthonormal_pair();
            [t1, t2]
        };
        let mut points = [ConstraintPoint::default(); MAX_MANIFOLD_POINTS];
        for (cp, p) in points.iter_mut().zip(&input.points[..input.count as usize]) {
            let ra = p.point - centers[ia];
            let rb = p.point - centers[ib];
            let relative = point_velocity(&states[ib], rb) - point_velocity(&states[ia], ra);
            *cp = ConstraintPoint {
                anchor_a: ra,
                anchor_b: rb,
                base_separation: p.separation - (rb - ra).dot(n),
                normal_mass: effective_mass(pa, pb, ra, rb, n),
                tangent_mass: tangents.map(|t| effective_mass(pa, pb, ra, rb, t)),
                relative_velocity: relative.dot(n),
                ..Default::default()
            };
        }
        Self {
            a: input.a,
            b: input.b,
            normal: n,
            tangents,
            friction: input.friction.max(0.0),
            restitution: input.restitution.max(0.0),
            softness,
            points,
            count: input.count,
            key: input.key,
            flip: false,
        }
    }

    /// The used points.
    pub fn points(&self) -> &[ConstraintPoint] {
        &self.points[..self.count as usize]
    }

    fn points_mut(&mut self) -> &mut [ConstraintPoint] {
        &mut self.points[..self.count as usize]
    }

    /// Applies the accumulated impulses (warm start): the previous substep's answer is the best
    /// first guess for this one.
    pub fn warm_start(&self, states: &mut [BodyState], params: &[BodyParams]) {
        let mut pair = Pair::load(self.a, self.b, states, params);
        for cp in self.points() {
            let p = self.normal * cp.normal_impulse
                + self.tangents[0] * cp.tangent_impulse[0]
                + self.tangents[1] * cp.tangent_impulse[1];
            pair.apply(cp.anchor_a, cp.anchor_b, p);
        }
        pair.store(states);
    }

    /// One pass over the rows: non-penetration (biased when `use_bias`), then friction when
    /// relaxing.
    pub fn solve(
        &mut self,
        states: &mut [BodyState],
        params: &[BodyParams],
        inv_h: f32,
        max_push_out: f32,
        use_bias: bool,
    ) {
        let mut pair = Pair::load(self.a, self.b, states, params);
        let (n, soft) = (self.normal, self.softness);
        let moved = pair.b.delta_position - pair.a.delta_position;
        let (dqa, dqb) = (pair.a.delta_rotation, pair.b.delta_rotation);
        let count = self.count as usize;
        for k in 0..count {
            // Gauss–Seidel favours the point it solves first; alternating the order every
            // substep keeps the corners of a resting box even (a 20-box stack sways 2.2 cm in
            // 10 s instead of 6.9 cm in one fixed order).
            let cp = &mut self.points[if self.flip { count - 1 - k } else { k }];
            let (ra, rb) = (cp.anchor_a, cp.anchor_b);
            let s = cp.base_separation + (moved + dqb * rb - dqa * ra).dot(n);
            let (bias, mass_scale, impulse_scale) = if s > 0.0 {
                (s * inv_h, 1.0, 0.0)
            } else if use_bias {
                let bias = (soft.mass_scale * soft.bias_rate * s).max(-max_push_out);
                (bias, soft.mass_scale, soft.impulse_scale)
            } else {
                (0.0, 1.0, 0.0)
            };
            let vn = pair.relative_velocity(ra, rb).dot(n);
            let impulse =
                -cp.normal_mass * (mass_scale * vn + bias) - impulse_scale * cp.normal_impulse;
            let total = (cp.normal_impulse + impulse).max(0.0);
            let applied = total - cp.normal_impulse;
            if cp.max_normal_impulse == 0.0 && total > 0.0 {
                cp.relative_velocity = vn;
            }
            cp.normal_impulse = total;
            cp.max_normal_impulse = cp.max_normal_impulse.max(total);
            pair.apply(ra, rb, n * applied);
        }
        if !use_bias && self.friction > 0.0 {
            let (t, mu) = (self.tangents, self.friction);
            for cp in self.points_mut() {
                let (ra, rb) = (cp.anchor_a, cp.anchor_b);
                let v = pair.relative_velocity(ra, rb);
                let wanted =
                    [0, 1].map(|k| cp.tangent_impulse[k] - cp.tangent_mass[k] * v.dot(t[k]));
                let limit = mu * cp.normal_impulse;
                let length = (wanted[0] * wanted[0] + wanted[1] * wanted[1]).sqrt();
                let scale = if length > limit && length > 0.0 {
                    limit / length
                } else {
                    1.0
                };
                let total = wanted.map(|w| w * scale);
                let delta = [0, 1].map(|k| total[k] - cp.tangent_impulse[k]);
                cp.tangent_impulse = total;
                pair.apply(ra, rb, t[0] * delta[0] + t[1] * delta[1]);
            }
        }
        pair.store(states);
    }

    /// After the substeps: points that approached faster than `threshold` and pushed get the
    /// separation speed `e` times their approach speed (Box2D's restitution pass).
    pub fn restitute(&mut self, states: &mut [BodyState], params: &[BodyParams], threshold: f32) {
        if self.restitution == 0.0 {
            return;
        }
        let mut pair = Pair::load(self.a, self.b, states, params);
        let (n, e) = (self.normal, self.restitution);
        for cp in self.points_mut() {
            if cp.relative_velocity > -threshold || cp.max_normal_impulse == 0.0 {
                continue;
            }
            let vn = pair.relative_velocity(cp.anchor_a, cp.anchor_b).dot(n);
            let impulse = -cp.normal_mass * (vn + e * cp.relative_velocity);
            let total = (cp.normal_impulse + impulse).max(0.0);
            let applied = total - cp.normal_impulse;
            cp.normal_impulse = total;
            pair.apply(cp.anchor_a, cp.anchor_b, n * applied);
        }
        pair.store(states);
    }
}

/// The two bodies of a constraint, copied out of the arrays for one pass (only dynamic bodies
/// are written back).
struct Pair {
    a: BodyState,
    b: BodyState,
    pa: BodyParams,
    pb: BodyParams,
    ia: usize,
    ib: usize,
}

impl Pair {
    fn load(a: u32, b: u32, states: &[BodyState], params: &[BodyParams]) -> Self {
        let (ia, ib) = (a as usize, b as usize);
        Self {
            a: states[ia],
            b: states[ib],
            pa: params[ia],
            pb: params[ib],
            ia,
            ib,
        }
    }

    fn relative_velocity(&self, ra: Vec3, rb: Vec3) -> Vec3 {
        point_velocity(&self.b, rb) - point_velocity(&self.a, ra)
    }

    /// Impulse `p` on B at `rb`, `−p` on A at `ra`.
    fn apply(&mut self, ra: Vec3, rb: Vec3, p: Vec3) {
        self.a.linear_velocity -= p * self.pa.inverse_mass;
        self.a.angular_velocity -= self.pa.inverse_inertia * ra.cross(p);
        self.b.linear_velocity += p * self.pb.inverse_mass;
        self.b.angular_velocity += self.pb.inverse_inertia * rb.cross(p);
    }

    fn store(self, states: &mut [BodyState]) {
        if self.pa.dynamic {
            states[self.ia] = self.a;
        }
        if self.pb.dynamic {
            states[self.ib] = self.b;
        }
    }
}

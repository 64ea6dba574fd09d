//! The velocities of a scalar contact constraint's two bodies during one pass
//! ([`ContactConstraint::solve`](super::contact::ContactConstraint)): copied out once, pushed by
//! each row's impulse, written back for the dynamic bodies only (Box2D v3's contact solver
//! keeps them in locals the same way). The four-lane batches have their own,
//! [`PairVelocities`](super::lanes::PairVelocities).

use super::body::BodyState;
use super::contact::{ContactConstraint, RowPart};
use super::patch_friction::PatchFriction;
use glam::Vec3;

/// How many times the friction disc's radius a point's rows must ask for before its impulse
/// turns to oppose its slip (see [`Pair::solve_disc`]); wholly from twice this.
pub(super) const SLIDING_FROM: f32 = 4.0;

/// The velocities of a constraint's two bodies, copied out for one pass (only dynamic bodies
/// are written back).
#[derive(Clone, Copy)]
pub(super) struct Pair {
    pub va: Vec3,
    pub wa: Vec3,
    pub vb: Vec3,
    pub wb: Vec3,
}

impl Pair {
    pub(super) fn load(c: &ContactConstraint, states: &[BodyState]) -> Self {
        let (a, b) = (&states[c.a as usize], &states[c.b as usize]);
        Self {
            va: a.linear_velocity,
            wa: a.angular_velocity,
            vb: b.linear_velocity,
            wb: b.angular_velocity,
        }
    }

    /// The rate of a row: `d·(v_b − v_a) + (r_b × d)·ω_b − (r_a × d)·ω_a`.
    pub(super) fn along(&self, dir: Vec3, row: &RowPart) -> f32 {
        dir.dot(self.vb - self.va) + row.arm[1].dot(self.wb) - row.arm[0].dot(self.wa)
    }

    /// An impulse `λ d` on B at its anchor, `−λ d` on A, through the row's angular velocity
    /// changes per unit impulse `turn` (`I⁻¹ (r × d)`; the lever arms are not needed).
    pub(super) fn push(&mut self, c: &ContactConstraint, dir: Vec3, turn: &[Vec3; 2], lambda: f32) {
        self.push_with(c.inverse_mass, dir, turn, lambda);
    }

    /// [`Self::push`] with the two per-axis inverse masses given.
    pub(super) fn push_with(
        &mut self,
        inverse_mass: [Vec3; 2],
        dir: Vec3,
        turn: &[Vec3; 2],
        lambda: f32,
    ) {
        // `d (W λ)` per component: with one `1/m` per body exactly the old `d (λ/m)`.
        self.va -= dir * (inverse_mass[0] * lambda);
        self.wa -= turn[0] * lambda;
        self.vb += dir * (inverse_mass[1] * lambda);
        self.wb += turn[1] * lambda;
    }

    /// Two tangent rows clamped together to the disc `|λ| ≤ limit` (Coulomb friction, at a
    /// point or a patch centre), each solving `J V + drift = 0` (`anchor_drift.rs`): the new
    /// accumulated impulses from the `old` ones.
    ///
    /// Each row takes its own mass `1/(J M⁻¹ Jᵀ)`, which is what stops a point, and the pair
    /// is clamped to the disc. But a point that slides on has Coulomb's force opposite its
    /// slip, and the rows' own masses tilt it: they differ with the lever arms (at a corner of
    /// a spinning plate up to 4:1), so `old − m_i v_i` points away from the slip and the clamp
    /// keeps that direction. A plate spinning on its four corners slowed at 95.4 % of
    /// Coulomb's rate, 92 % over some tenths of a second. So a point that asks for more than
    /// [`SLIDING_FROM`] times what the disc allows (it slides for that many more substeps at
    /// least) takes its impulse from one mass for both rows (their mean), `old − m̄ v`, the
    /// slip's direction blended with the impulse held; at twice that, wholly. Closer to the
    /// disc the rows' own masses stay: taking the slip's direction there (a point being
    /// stopped) slowed a cylinder rolling across a tessellated floor at its seams (2.80
    /// against 2.88 m/s after 2 s of 3).
    pub(super) fn solve_disc(
        &mut self,
        [r0, r1]: &[RowPart; 2],
        [t0, t1]: [Vec3; 2],
        ([old0, old1], [drift0, drift1]): ([f32; 2], [f32; 2]),
        (limit, inverse_mass): (f32, [Vec3; 2]),
    ) -> [f32; 2] {
        // Written out, not `[0, 1].map(..)`: the array map's drain was a tenth of the
        // solver's instructions (callgrind).
        let (v0, v1) = (self.along(t0, r0) + drift0, self.along(t1, r1) + drift1);
        let w0 = old0 - r0.mass * v0;
        let w1 = old1 - r1.mass * v1;
        let length = (w0 * w0 + w1 * w1).sqrt();
        let [new0, new1] = if length > limit && length > 0.0 {
            let mean = 0.5 * (r0.mass + r1.mass);
            let slid = ((length / limit - SLIDING_FROM) / SLIDING_FROM).clamp(0.0, 1.0);
            let s0 = w0 + slid * (old0 - mean * v0 - w0);
            let s1 = w1 + slid * (old1 - mean * v1 - w1);
            let slide = (s0 * s0 + s1 * s1).sqrt();
            // Where `old − m̄ v` is nothing, the rows' own direction.
            let (u0, u1, length) = if slide > 0.0 {
                (s0, s1, slide)
            } else {
                (w0, w1, length)
            };
            [u0 * (limit / length), u1 * (limit / length)]
        } else {
            [w0, w1]
        };
        self.push_with(inverse_mass, t0, &r0.turn, new0 - old0);
        self.push_with(inverse_mass, t1, &r1.turn, new1 - old1);
        [new0, new1]
    }

    /// A patch's friction ([`PatchFriction`]): the twist about the normal `n`, then the
    /// tangent disc at the centre, within `(μ Σλ_i, μ Σλ_i d_i)`, aiming at `share` of its
    /// drift targets.
    pub(super) fn solve_patch(
        &mut self,
        patch: &mut PatchFriction,
        (limit, twist_limit): (f32, f32),
        (n, tangents): (Vec3, [Vec3; 2]),
        (inverse_mass, share): ([Vec3; 2], f32),
    ) {
        let old = patch.twist_impulse;
        if limit == 0.0 && old == 0.0 && patch.tangent_impulse == [0.0; 2] {
            // No normal force, no friction held (a speculative contact still apart).
            return;
        }
        let wanted = old - patch.twist_mass * n.dot(self.wb - self.wa);
        let twist = wanted.max(-twist_limit).min(twist_limit);
        self.twist(patch, twist - old);
        patch.twist_impulse = twist;
        let rows = &patch.tangent_rows;
        let [drift0, drift1] = patch.tangent_drift;
        let old = (patch.tangent_impulse, [drift0 * share, drift1 * share]);
        patch.tangent_impulse = self.solve_disc(rows, tangents, old, (limit, inverse_mass));
    }

    /// An angular impulse `λ n` on B, `−λ n` on A (the twist row).
    pub(super) fn twist(&mut self, patch: &PatchFriction, lambda: f32) {
        self.wa -= patch.twist_turn[0] * lambda;
        self.wb += patch.twist_turn[1] * lambda;
    }

    pub(super) fn store(self, c: &ContactConstraint, states: &mut [BodyState]) {
        if c.dynamic[0] {
            let s = &mut states[c.a as usize];
            s.linear_velocity = self.va;
            s.angular_velocity = self.wa;
        }
        if c.dynamic[1] {
            let s = &mut states[c.b as usize];
            s.linear_velocity = self.vb;
            s.angular_velocity = self.wb;
        }
    }
}

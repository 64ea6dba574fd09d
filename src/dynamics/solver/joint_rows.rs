//! The pure constraint math of joints: the rows a joint is made of, their Jacobians, effective
//! masses and impulses, apart from any joint kind (as Avian's `dynamics/solver/joints` keeps
//! its `PointConstraintPart`s apart, and Jolt its `AxisConstraintPart`,
//! `PointConstraintPart` and `RotationEulerConstraintPart`).
//!
//! Every row works on the velocities `V = (v_a, ω_a, v_b, ω_b)` of two bodies with inverse
//! masses `m_a⁻¹`, `m_b⁻¹` and world inverse inertias `I_a⁻¹`, `I_b⁻¹`. A body with locked
//! translation axes has the diagonal `W = diag(m⁻¹ per axis)`, 0 along a locked one, in place
//! of `m⁻¹ 1` wherever it appears below. A row with Jacobian
//! `J` has the velocity error `Ċ = J V`, the effective mass `K⁻¹` with `K = J M⁻¹ Jᵀ`, and an
//! impulse `λ` changes the velocities by `M⁻¹ Jᵀ λ`. The soft form of the impulse
//! (`λ = −mass_scale K⁻¹ (Ċ + bias) − impulse_scale λ_acc`) is [`Softness`]'s.
//!
//! * [`AxisRow`]: one scalar row `J = [−lᵀ, −u_aᵀ, lᵀ, u_bᵀ]` (a hinge's angle `l = 0`,
//!   `u_a = u_b = axis`; a slider's travel and a rope's length, see the joints).
//! * The three point rows keeping two anchors together (a ball joint): in
//!   [`point_rows`](super::point_rows).
//! * [`AngularRows`]: two or three rows on the relative angular velocity alone,
//!   `Ċ_i = u_i · (ω_b − ω_a)`, `J_i = [0, −u_iᵀ, 0, u_iᵀ]`, `K_ij = u_i · (I_a⁻¹ + I_b⁻¹) u_j`
//!   (a weld's lock: `u` the world axes; a hinge's alignment: two directions, see
//!   [`hinge_directions`]).

use super::body::{BodyParams, BodyState, same_on_every_axis};
use super::point_rows::inverse_mass;
use super::softness::Softness;
use glam::{Mat3, Vec3};

/// The two bodies of a joint as its rows see them: masses and world inverse inertias.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairMasses {
    /// `m_a⁻¹`, `m_b⁻¹` per world axis (0 along a locked translation axis).
    pub inverse_mass: [Vec3; 2],
    /// `I_a⁻¹`, `I_b⁻¹` (world, at the step's start).
    pub inverse_inertia: [Mat3; 2],
    /// Whether the solver may change each body's velocities.
    pub dynamic: [bool; 2],
}

impl PairMasses {
    /// Takes the masses of bodies `a` and `b`, written in place field by field: a whole
    /// `PairMasses` built and then moved into its joint went through the stack in pieces of
    /// 12 and 36 bytes, and the wider loads of the move waited for those stores to land (no
    /// store-to-load forwarding), a third of a joint net's refills.
    #[inline]
    pub fn fill(&mut self, params: &[BodyParams], a: usize, b: usize) {
        let (pa, pb) = (&params[a], &params[b]);
        self.inverse_mass[0] = pa.inverse_mass;
        self.inverse_mass[1] = pb.inverse_mass;
        self.inverse_inertia[0] = pa.inverse_inertia;
        self.inverse_inertia[1] = pb.inverse_inertia;
        self.dynamic = [pa.dynamic, pb.dynamic];
    }

    /// Applies the impulse `λ` of a row, linear part `l λ`, angular parts `u_a λ`, `u_b λ`:
    /// `v_a −= W_a l λ` (`W` the per-axis `1/m`), `ω_a −= I_a⁻¹ u_a λ`, and the opposite
    /// signs for B. Always inlined, for the reason [`inverse_mass`] is: its `Vec3`
    /// arguments went through memory, and their loads waited on the caller's stores.
    #[inline(always)]
    pub fn apply(
        &self,
        states: &mut [BodyState],
        (a, b): (usize, usize),
        linear: Vec3,
        angular: [Vec3; 2],
    ) {
        if self.dynamic[0] {
            let s = &mut states[a];
            s.linear_velocity -= linear * self.inverse_mass[0];
            s.angular_velocity -= self.inverse_inertia[0] * angular[0];
        }
        if self.dynamic[1] {
            let s = &mut states[b];
            s.linear_velocity += linear * self.inverse_mass[1];
            s.angular_velocity += self.inverse_inertia[1] * angular[1];
        }
    }
}

/// One scalar row `J = [−lᵀ, −u_aᵀ, lᵀ, u_bᵀ]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisRow {
    /// The linear direction `l`.
    pub linear: Vec3,
    /// A's angular direction `u_a`.
    pub angular_a: Vec3,
    /// B's angular direction `u_b`.
    pub angular_b: Vec3,
    /// For an angular row of a joint that also holds its anchors together: turn each body
    /// about its anchor instead of its centre of mass ([`Pivot`]).
    pub pivot: Option<Pivot>,
}

/// How an angular row of a joint that also holds its anchors together moves its bodies: with
/// the point rows' answer folded in. A unit impulse along the row alone turns the bodies by
/// `w_a = −I_a⁻¹ u_a`, `w_b = I_b⁻¹ u_b`, which moves the anchors apart at
/// `d = w_b × r_b − w_a × r_a`; the point rows answer with `P = −K_p⁻¹ d` (see
/// [`point_mass`](super::point_rows::point_mass)). The row's impulse and that answer together change the velocities by
/// `Δv_a = −m_a⁻¹ P`, `Δω_a = w_a − I_a⁻¹ (r_a × P)`, `Δv_b = m_b⁻¹ P`,
/// `Δω_b = w_b + I_b⁻¹ (r_b × P)`, and the row's velocity by `K = u_b·Δω_b − u_a·Δω_a`: the
/// effective mass of the row with the anchors held (the Schur complement of the point rows).
/// Solved about the centres instead, a limb pinned at its end takes only `I/I'` of the impulse
/// it needs (a quarter for a bar), the point rows hand the rest back as rotation, and a swing
/// cone gave way by 2° under a kick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pivot {
    /// `Δv_a, Δω_a, Δv_b, Δω_b` per unit impulse.
    pub response: [Vec3; 4],
    /// The point rows' answer `P` per unit impulse (on B; A takes `−P`): the force a joint
    /// holds includes it (a hinge's limit holding a level arm carries three quarters of the
    /// arm's weight this way).
    pub point: Vec3,
    /// The row's velocity change per unit impulse.
    pub k: f32,
}

impl Pivot {
    /// The pivot of the angular row `(u_a, u_b)` between bodies with masses `m` held together
    /// at anchors `r_a`, `r_b` by point rows of effective mass `point_k_inverse` (the joint's
    /// own, taken once per substep: [`point_mass`](super::point_rows::point_mass) inverted by [`inverse_mass`]).
    pub fn new(
        m: &PairMasses,
        (u_a, u_b): (Vec3, Vec3),
        (r_a, r_b): (Vec3, Vec3),
        point_k_inverse: &Mat3,
    ) -> Self {
        let [ia, ib] = m.inverse_inertia;
        let (w_a, w_b) = (-(ia * u_a), ib * u_b);
        let d = w_b.cross(r_b) - w_a.cross(r_a);
        let p = -(*point_k_inverse * d);
        let [ma, mb] = m.inverse_mass;
        let dw_a = w_a - ia * r_a.cross(p);
        let dw_b = w_b + ib * r_b.cross(p);
        let keep = |dynamic: bool, v: Vec3| if dynamic { v } else { Vec3::ZERO };
        Self {
            response: [
                keep(m.dynamic[0], -p * ma),
                keep(m.dynamic[0], dw_a),
                keep(m.dynamic[1], p * mb),
                keep(m.dynamic[1], dw_b),
            ],
            k: u_b.dot(dw_b) - u_a.dot(dw_a),
            point: p,
        }
    }
}

impl AxisRow {
    /// A row on the relative turn about `axis` (a hinge's angle).
    pub fn angular(axis: Vec3) -> Self {
        Self {
            linear: Vec3::ZERO,
            angular_a: axis,
            angular_b: axis,
            pivot: None,
        }
    }

    /// The angular row with its bodies held together at anchors `(r_a, r_b)` by point rows of
    /// effective mass `point_k_inverse` (see [`Pivot`]).
    pub fn held_at(
        mut self,
        m: &PairMasses,
        anchors: (Vec3, Vec3),
        point_k_inverse: &Mat3,
    ) -> Self {
        let dirs = (self.angular_a, self.angular_b);
        self.pivot = Some(Pivot::new(m, dirs, anchors, point_k_inverse));
        self
    }

    /// A row along `direction` between anchors `r_a`, `r_b` (a slider's travel uses its own
    /// `u_a`, see the prismatic joint).
    pub fn linear(direction: Vec3, r_a: Vec3, r_b: Vec3) -> Self {
        Self {
            linear: direction,
            angular_a: r_a.cross(direction),
            angular_b: r_b.cross(direction),
            pivot: None,
        }
    }

    /// `Ċ = J V`.
    pub fn velocity(&self, sa: &BodyState, sb: &BodyState) -> f32 {
        self.linear.dot(sb.linear_velocity - sa.linear_velocity)
            + self.angular_b.dot(sb.angular_velocity)
            - self.angular_a.dot(sa.angular_velocity)
    }

    /// `K = J M⁻¹ Jᵀ` (with the anchors held, for a row [`held_at`](Self::held_at) them).
    pub fn k(&self, m: &PairMasses) -> f32 {
        if let Some(p) = &self.pivot {
            return p.k;
        }
        let [ia, ib] = m.inverse_inertia;
        let w = m.inverse_mass[0] + m.inverse_mass[1];
        let linear = if same_on_every_axis(w) {
            w.x * self.linear.length_squared()
        } else {
            w.dot(self.linear * self.linear)
        };
        linear + self.angular_a.dot(ia * self.angular_a) + self.angular_b.dot(ib * self.angular_b)
    }

    /// Applies `λ` along the row.
    pub fn apply(&self, m: &PairMasses, states: &mut [BodyState], ab: (usize, usize), lambda: f32) {
        if let Some(p) = &self.pivot {
            let [va, wa, vb, wb] = p.response;
            states[ab.0].linear_velocity += va * lambda;
            states[ab.0].angular_velocity += wa * lambda;
            states[ab.1].linear_velocity += vb * lambda;
            states[ab.1].angular_velocity += wb * lambda;
            return;
        }
        m.apply(
            states,
            ab,
            self.linear * lambda,
            [self.angular_a * lambda, self.angular_b * lambda],
        );
    }

    /// Solves the row towards `Ċ = target − bias` (soft when `soft` is given) and clamps the
    /// accumulated impulse to `range`; returns the impulse applied.
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &self,
        m: &PairMasses,
        states: &mut [BodyState],
        (a, b): (usize, usize),
        bias: f32,
        soft: Softness,
        accumulated: &mut f32,
        range: (f32, f32),
    ) -> f32 {
        let cdot = self.velocity(&states[a], &states[b]);
        let Some(impulse) = self.impulse(m, cdot + bias, soft, *accumulated) else {
            return 0.0;
        };
        let old = *accumulated;
        *accumulated = (old + impulse).clamp(range.0, range.1);
        let applied = *accumulated - old;
        self.apply(m, states, (a, b), applied);
        applied
    }

    /// Solves the row pushing towards `side` only (`+1` along it, `−1` against it: the row
    /// reversed, without building it), its velocity that way `cdot` (`side · Ċ`, taken by the
    /// caller, who skips a bound that carries nothing and is not closing faster than `bias`
    /// allows before the row's mass is needed): the accumulated impulse stays `≥ 0`, and a NaN
    /// impulse (from NaN velocities) leaves it carrying nothing. Returns the impulse applied.
    #[allow(clippy::too_many_arguments)]
    pub fn push_only(
        &self,
        m: &PairMasses,
        states: &mut [BodyState],
        ab: (usize, usize),
        (side, cdot): (f32, f32),
        bias: f32,
        soft: Softness,
        accumulated: &mut f32,
    ) -> f32 {
        let Some(impulse) = self.impulse(m, cdot + bias, soft, *accumulated) else {
            return 0.0;
        };
        let old = *accumulated;
        *accumulated = (old + impulse).max(0.0);
        let applied = *accumulated - old;
        if applied != 0.0 {
            self.apply(m, states, ab, side * applied);
        }
        applied
    }

    /// The soft impulse `−mass_scale (Ċ + bias)/K − impulse_scale λ_acc` for `error = Ċ + bias`,
    /// or none when the row has no usable mass (`K` zero or NaN: two immovable bodies).
    fn impulse(&self, m: &PairMasses, error: f32, soft: Softness, accumulated: f32) -> Option<f32> {
        let k = self.k(m);
        (k > 0.0).then(|| -soft.mass_scale * error / k - soft.impulse_scale * accumulated)
    }
}

/// Two or three rows on the relative angular velocity (see the module doc); the directions
/// are world axes at the step's start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AngularRows {
    /// The row directions (two used when `count == 2`).
    pub directions: [Vec3; 3],
    /// 2 or 3.
    pub count: usize,
}

impl AngularRows {
    /// The three world axes: a lock of the relative turn.
    pub fn world() -> Self {
        Self {
            directions: [Vec3::X, Vec3::Y, Vec3::Z],
            count: 3,
        }
    }

    /// `K⁻¹` of the rows (the unused third row of two is the identity, and takes nothing).
    pub fn inverse_mass(&self, m: &PairMasses) -> Mat3 {
        inverse_mass(self.k(m))
    }

    /// `K` restricted to the rows.
    fn k(&self, m: &PairMasses) -> Mat3 {
        let i = m.inverse_inertia[0] + m.inverse_inertia[1];
        let d = self.directions;
        let mut k = Mat3::IDENTITY;
        for r in 0..self.count {
            for c in 0..self.count {
                k.col_mut(c)[r] = d[r].dot(i * d[c]);
            }
        }
        k
    }

    /// Solves the rows towards zero relative turn, with per-row position errors `error`
    /// (`None` in a relax pass) and the rows' `k_inverse` ([`Self::inverse_mass`]);
    /// `accumulated` holds one impulse per row. Returns the world angular impulse applied to B.
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &self,
        m: &PairMasses,
        states: &mut [BodyState],
        (a, b): (usize, usize),
        error: Option<Vec3>,
        soft: Softness,
        k_inverse: &Mat3,
        accumulated: &mut Vec3,
    ) -> Vec3 {
        let relative = states[b].angular_velocity - states[a].angular_velocity;
        let d = self.directions;
        let mut cdot = Vec3::ZERO;
        for (r, dir) in d.iter().enumerate().take(self.count) {
            cdot[r] = dir.dot(relative);
        }
        let (bias, soft) = match error {
            Some(c) => (c * soft.bias_rate, soft),
            None => (Vec3::ZERO, Softness::RIGID),
        };
        let mut impulse =
            -soft.mass_scale * (*k_inverse * (cdot + bias)) - soft.impulse_scale * *accumulated;
        if self.count == 2 {
            impulse.z = 0.0;
        }
        *accumulated += impulse;
        let world = d[0] * impulse.x + d[1] * impulse.y + d[2] * impulse.z;
        m.apply(states, (a, b), Vec3::ZERO, [world, world]);
        world
    }
}

/// The two directions of a hinge's alignment rows: with `axis_a` on A and `perp_b`, `perp_b2`
/// on B perpendicular to B's axis, `C = (axis_a · p_1, axis_a · p_2)` is zero when the axes
/// agree, and `d/dt (axis_a · p) = (ω_a × axis_a)·p + axis_a·(ω_b × p)
/// = (ω_b − ω_a) · (p × axis_a)`: the row directions are `p_i × axis_a` (Jolt's
/// `HingeRotationConstraintPart`).
pub fn hinge_directions(axis_a: Vec3, perp_b: [Vec3; 2]) -> ([Vec3; 2], [f32; 2]) {
    (
        [perp_b[0].cross(axis_a), perp_b[1].cross(axis_a)],
        [axis_a.dot(perp_b[0]), axis_a.dot(perp_b[1])],
    )
}

#[cfg(test)]
pub(super) mod tests {
    use super::super::point_rows::point_mass;
    use super::*;

    /// Two bodies of masses `ma`, `mb` with unequal diagonal inverse inertias.
    pub(in crate::dynamics::solver) fn masses(ma: f32, mb: f32) -> PairMasses {
        PairMasses {
            inverse_mass: [Vec3::splat(1.0 / ma), Vec3::splat(1.0 / mb)],
            inverse_inertia: [
                Mat3::from_diagonal(Vec3::new(1.0, 2.0, 3.0)),
                Mat3::from_diagonal(Vec3::new(0.5, 0.25, 4.0)),
            ],
            dynamic: [true, true],
        }
    }

    /// Solves `row` rigidly, unbounded, from no accumulated impulse; returns the impulse.
    fn solve_unbounded(row: &AxisRow, m: &PairMasses, states: &mut [BodyState]) -> f32 {
        let mut acc = 0.0;
        let free = (f32::NEG_INFINITY, f32::INFINITY);
        row.solve(m, states, (0, 1), 0.0, Softness::RIGID, &mut acc, free);
        acc
    }

    #[test]
    fn an_axis_row_conserves_momentum_and_zeroes_its_velocity_within_1e_6() {
        let m = masses(1.0, 4.0);
        let mut states = [BodyState::default(); 2];
        states[0].linear_velocity = Vec3::X;
        let row = AxisRow::linear(Vec3::X, Vec3::ZERO, Vec3::ZERO);
        solve_unbounded(&row, &m, &mut states);
        let p = states[0].linear_velocity + 4.0 * states[1].linear_velocity;
        assert!((p - Vec3::X).length() < 1e-6);
        assert!(row.velocity(&states[0], &states[1]).abs() < 1e-6);
    }

    #[test]
    fn three_angular_rows_stop_the_relative_turn_and_two_leave_the_hinge_axis_free() {
        let m = masses(1.0, 1.0);
        let mut states = [BodyState::default(); 2];
        states[1].angular_velocity = Vec3::new(1.0, 2.0, 3.0);
        let lock = AngularRows {
            directions: [Vec3::X, Vec3::Y, Vec3::Z],
            count: 3,
        };
        let mut acc = Vec3::ZERO;
        let mut locked = states;
        let k = lock.inverse_mass(&m);
        lock.solve(&m, &mut locked, (0, 1), None, Softness::RIGID, &k, &mut acc);
        let rel = locked[1].angular_velocity - locked[0].angular_velocity;
        assert!(rel.length() < 1e-5, "{rel}");
        let hinge = AngularRows {
            directions: [Vec3::X, Vec3::Y, Vec3::ZERO],
            count: 2,
        };
        let mut acc = Vec3::ZERO;
        let k = hinge.inverse_mass(&m);
        hinge.solve(&m, &mut states, (0, 1), None, Softness::RIGID, &k, &mut acc);
        let rel = states[1].angular_velocity - states[0].angular_velocity;
        assert!(rel.x.abs() < 1e-5 && rel.y.abs() < 1e-5, "{rel}");
        assert!((rel.z - 3.0).abs() < 1e-5, "the free axis kept {rel}");
    }

    #[test]
    fn a_row_held_at_the_anchors_stops_the_turn_and_leaves_the_anchor_still_within_1e_5() {
        // A bar's end pinned to an immovable body: stop its turn about y in one solve.
        let mut m = masses(1.0, 1.0);
        m.inverse_mass[0] = Vec3::ZERO;
        m.inverse_inertia[0] = Mat3::ZERO;
        m.dynamic[0] = false;
        m.inverse_inertia[1] = Mat3::from_diagonal(Vec3::new(12.0, 12.0, 600.0));
        let r_b = Vec3::new(0.0, 0.0, 0.5);
        let mut states = [BodyState::default(); 2];
        states[1].angular_velocity = Vec3::Y * 2.0;
        states[1].linear_velocity = -(Vec3::Y * 2.0).cross(r_b);
        let point = inverse_mass(point_mass(&m, Vec3::ZERO, r_b));
        let row = AxisRow::angular(Vec3::Y).held_at(&m, (Vec3::ZERO, r_b), &point);
        let acc = solve_unbounded(&row, &m, &mut states);
        let s = states[1];
        assert!(s.angular_velocity.length() < 1e-5, "{}", s.angular_velocity);
        let anchor = s.linear_velocity + s.angular_velocity.cross(r_b);
        assert!(anchor.length() < 1e-5, "{anchor}");
        // The impulse is the one about the pivot: I' ω = (1/12 + 1/4) · 2.
        assert!(
            (acc.abs() - (1.0 / 12.0 + 0.25) * 2.0).abs() < 1e-4,
            "{acc}"
        );
    }

    #[test]
    fn a_nan_velocity_leaves_a_one_sided_row_carrying_nothing_instead_of_nan() {
        let m = masses(1.0, 2.0);
        let mut states = [BodyState::default(); 2];
        states[1].linear_velocity = Vec3::new(f32::NAN, 0.0, 0.0);
        let row = AxisRow::linear(Vec3::X, Vec3::ZERO, Vec3::ZERO);
        let mut acc = 0.5;
        let cdot = row.velocity(&states[0], &states[1]);
        let rigid = Softness::RIGID;
        row.push_only(&m, &mut states, (0, 1), (1.0, cdot), 0.0, rigid, &mut acc);
        assert_eq!(acc, 0.0);
        // The good body takes back the row's impulse, a finite change.
        assert!(states[0].linear_velocity.is_finite());
    }
}

//! The normal rows of one contact ([`ContactConstraint`]), solved point by point
//! (Gauss–Seidel), and its bounces after the substeps.
//!
//! # Sweeps until the points agree
//! One sweep over a contact's points favours the point it solves first. A unit box dropped
//! flat from 14 cm to 2 m had its first corner stop the whole box and the others answer the
//! turn that gave it: it left the impact spinning at 0.08–0.44 rad/s (0.34–1.8 rad/s with a
//! restitution of 0.5, the bounces being one sweep too), and its friction turned that into a
//! slide of up to 0.2 m/s (`scenarios/landing.rs`). rapier's solver does the same (0.17–0.45
//! and 0.33–1.16 rad/s on the same drops, a scratch scene of `peers/`), as would Box2D v3's,
//! whose passes are ours. The four points of a flat
//! face are a degenerate system (three degrees of freedom, four rows), which one sweep cannot
//! settle but a few do. So a pass sweeps an impact's points ([`IMPACT_SPEED`]) again, in the
//! other order, while its last sweep changed some point's normal speed by more than
//! [`SETTLED_SPEED`], at most [`MAX_SWEEPS`] times; the bounces likewise, finer
//! ([`BOUNCE_SETTLED_SPEED`]). Other contacts, whose warm start already holds most of the
//! answer, keep one sweep a pass.
//!
//! # One moment per impact
//! Restitution reverses each point's approach speed, read when the point first pushes. Read
//! point by point, a face landing flat read its points at different moments: the first to push
//! (a speculative push, a substep before touching, that closes only its own gap) turned the
//! body, and the points that pushed a substep later read the turn. A cylinder dropped 1 m
//! flat onto a mesh floor, its cap over a grid vertex (four points of its cap, spread
//! unevenly by the seams), read 3.82 m/s at one point and 4.41 at three, and its bounce of
//! restitution 1 spun it at 1.8 rad/s: it landed upside down. So the first push of a contact
//! in a step reads every point's speed at once, from the velocities before the pass, each at
//! its own gap, and the points' later first pushes keep it. A contact already pushing at the
//! step's start (its warm start) keeps the speeds its points had then, as Box2D v3 reads them
//! all (which, for an impact, loses the speed gravity adds before it: [`impact_speed`]).
//!
//! # Rounded sides roll
//! A point's separation follows its anchors as material points of the bodies (Box2D v3): a
//! ball that rolls by `θ` lifts its anchor by `R (1 − cos θ)`, though its surface under the
//! centre stays where it was. A ball rolling at 10 rad/s lifted 0.35 mm in a step at 60 Hz,
//! so the later substeps saw it apart and let it fall, and its support came in the first
//! ones: 75 % and 25 % of it in the first two of four substeps, none in the last two, and the
//! friction of those substeps none. A rounded side (`ContactConstraint::rounding` `ρ`, a
//! ball's or capsule's radius) turns its core point `r ± ρ n` instead and keeps `ρ` along
//! the normal: the separation gains `ρ_b (n·n_b − 1) + ρ_a (n·n_a − 1)` per pass
//! ([`rolled`]), zero for a body that has not turned, and a rolling ball is held in every
//! substep alike.

use super::*;

/// Most sweeps a pass makes over a contact's normal rows, and over its bounces.
pub const MAX_SWEEPS: usize = 8;

/// Normal speed (m/s) above which a point at the step's start makes its contact an impact,
/// whose points are swept until they agree; the others are swept once a pass. Why not every
/// contact: whether a sweep settles is a threshold, and a threshold crossed in one run and not
/// in another sends two nearly equal scenes apart (with every contact swept until settled, a
/// scene 1 km from the origin strayed 13 float spacings from the same scene at the origin
/// where a ball struck a resting box, `tests/stability.rs` bounds it at 8; the resting box's
/// contact is no impact). A resting contact closes at most gravity's pull over a step
/// (0.16 m/s at 60 Hz) before its warm start.
pub const IMPACT_SPEED: f32 = 0.25;

/// A sweep that changed no point's normal speed by more than this (m/s) ends the sweeps: well
/// above what a resting contact's sweep changes (its warm start holds gravity's pull), well
/// below a landing that visibly tips a box.
pub const SETTLED_SPEED: f32 = 0.1;

/// [`SETTLED_SPEED`] for the bounces (m/s), finer: they are few (only points that met the
/// surface faster than the restitution threshold), and what a sweep leaves unsettled there
/// turns into a spin the body keeps for its whole flight.
pub const BOUNCE_SETTLED_SPEED: f32 = 1e-3;

/// What rounded sides (`rounding`, A's and B's) add to every point's separation when their
/// bodies have turned the normal `n` to `turned` (A's, B's) since the step's start (module
/// docs): `ρ_a n·(n_a − n) + ρ_b n·(n_b − n)`, exactly zero for a body that has not turned.
#[inline]
pub(super) fn rolled(rounding: [f32; 2], n: Vec3, turned: [Vec3; 2]) -> f32 {
    rounding[0] * n.dot(turned[0] - n) + rounding[1] * n.dot(turned[1] - n)
}

/// How a contact's bodies moved since the step's start, as its separations read it.
struct Motion {
    /// `(Δp_b − Δp_a)·n`: the bodies' motion along the normal (with what rounded sides roll).
    moved: f32,
    /// The normal turned back into A's and B's rotation.
    turned: [Vec3; 2],
}

/// What each sweep of one pass over a contact's normal rows reads, taken once per pass.
struct NormalPass {
    motion: Motion,
    inv_h: f32,
    max_push_out: f32,
    use_bias: bool,
}

impl ContactConstraint {
    /// One pass over the normal rows (module docs): speculative points close their gap,
    /// penetrating ones are pushed out softly when `use_bias`.
    pub(super) fn solve_normals(
        &mut self,
        pair: &mut Pair,
        states: &[BodyState],
        (inv_h, max_push_out): (f32, f32),
        use_bias: bool,
    ) {
        let pass = NormalPass {
            motion: self.motion(states),
            inv_h,
            max_push_out,
            use_bias,
        };
        // The velocities before this pass's impulses, from which a point that first pushes
        // reads its impact speed (see `ConstraintPoint::relative_velocity`).
        let before = *pair;
        // Gauss–Seidel favours the point it solves first; alternating the order every substep
        // keeps the corners of a resting box even (a 20-box stack sways 2.2 cm in 10 s instead
        // of 6.9 cm in one fixed order), and every sweep again.
        let mut backwards = self.flip;
        // One sweep solves a lone point's row exactly: balls need no second.
        let sweeps = if self.count > 1 && self.impact {
            MAX_SWEEPS
        } else {
            1
        };
        for _ in 0..sweeps {
            if !self.sweep_normals(pair, &before, &pass, backwards) {
                break;
            }
            backwards = !backwards;
        }
    }

    /// One sweep over the points; whether it changed some point's normal speed by more than
    /// [`SETTLED_SPEED`].
    fn sweep_normals(
        &mut self,
        pair: &mut Pair,
        before: &Pair,
        pass: &NormalPass,
        backwards: bool,
    ) -> bool {
        let (n, soft, count) = (self.normal, self.softness, self.count as usize);
        let mut unsettled = false;
        for k in 0..count {
            let i = if backwards { count - 1 - k } else { k };
            let s = self.separation(&self.points[i], &pass.motion);
            let cp = &mut self.points[i];
            let (bias, mass_scale, impulse_scale) = if s > 0.0 {
                (s * pass.inv_h, 1.0, 0.0)
            } else if pass.use_bias {
                let bias = (soft.mass_scale * soft.bias_rate * s).max(-pass.max_push_out);
                (bias, soft.mass_scale, soft.impulse_scale)
            } else {
                (0.0, 1.0, 0.0)
            };
            let row = &cp.row(&cp.normal_row, n);
            let vn = pair.along(n, row);
            let impulse = -row.mass * (mass_scale * vn + bias) - impulse_scale * cp.normal_impulse;
            let total = (cp.normal_impulse + impulse).max(0.0);
            let applied = total - cp.normal_impulse;
            // `applied / mass` is the change of the point's normal speed.
            unsettled |= applied.abs() > SETTLED_SPEED * row.mass;
            pair.push_with(self.inverse_mass, n, &row.turn, applied);
            let first_push = cp.max_normal_impulse == 0.0 && total > 0.0;
            if first_push
                && self.points[..count]
                    .iter()
                    .all(|p| p.max_normal_impulse == 0.0)
            {
                self.time_impact(before, pass);
            }
            let cp = &mut self.points[i];
            cp.normal_impulse = total;
            cp.max_normal_impulse = cp.max_normal_impulse.max(total);
        }
        unsettled
    }

    /// How the bodies in `states` moved since the step's start, along the normal.
    #[inline(always)]
    fn motion(&self, states: &[BodyState]) -> Motion {
        let (sa, sb) = (&states[self.a as usize], &states[self.b as usize]);
        let n = self.normal;
        // The current separation of a point is `s₀' + (Δp_b − Δp_a + Δq_b r_b − Δq_a r_a)·n`;
        // with `(Δq r)·n = r·(Δq⁻¹ n)` the normal is turned back into each body's rotation
        // since the step's start once per contact instead of turning every anchor (a box on a
        // box has four points: two rotations a pass instead of eight).
        let turned = [
            sa.delta_rotation.inverse() * n,
            sb.delta_rotation.inverse() * n,
        ];
        let mut moved = (sb.delta_position - sa.delta_position).dot(n);
        if self.rounding != [0.0; 2] {
            moved += rolled(self.rounding, n, turned);
        }
        Motion { moved, turned }
    }

    /// The current separation of point `cp`, the bodies having moved by `m`.
    #[inline(always)]
    fn separation(&self, cp: &ConstraintPoint, m: &Motion) -> f32 {
        let [na, nb] = m.turned;
        let ra = on_moving(self.still[0], cp.anchor_a);
        let rb = on_moving(self.still[1], cp.anchor_b);
        cp.base_separation + m.moved + rb.dot(nb) - ra.dot(na)
    }

    /// The impact speeds of all the points (module docs, "One moment per impact"), read from
    /// the velocities `before` the pass: called when the contact first pushes in the step.
    #[cold]
    fn time_impact(&mut self, before: &Pair, pass: &NormalPass) {
        let n = self.normal;
        for k in 0..self.count as usize {
            let s = self.separation(&self.points[k], &pass.motion);
            let cp = &mut self.points[k];
            let vn = before.along(n, &cp.row(&cp.normal_row, n));
            cp.relative_velocity = impact_speed(vn, s, self.closing_acceleration);
        }
    }

    /// Restitution after the substeps: each point that pushed and met the surface faster than
    /// `threshold` leaves it at `e` times that speed (Box2D v3's `b2ApplyRestitution`), its
    /// points swept until they agree (module docs).
    pub fn restitute(&mut self, states: &mut [BodyState], threshold: f32) {
        let count = self.count as usize;
        let bounces = |cp: &ConstraintPoint| {
            cp.relative_velocity <= -threshold && cp.max_normal_impulse > 0.0
        };
        if self.restitution == 0.0 || !self.points[..count].iter().any(bounces) {
            return;
        }
        let mut pair = Pair::load(self, states);
        let (n, e) = (self.normal, self.restitution);
        let mut backwards = false;
        for _ in 0..if count > 1 { MAX_SWEEPS } else { 1 } {
            let mut unsettled = false;
            for k in 0..count {
                let i = if backwards { count - 1 - k } else { k };
                let cp = self.points[i];
                if !bounces(&cp) {
                    continue;
                }
                let row = &cp.row(&cp.normal_row, n);
                let vn = pair.along(n, row);
                let impulse = -row.mass * (vn + e * cp.relative_velocity);
                let total = (cp.normal_impulse + impulse).max(0.0);
                let applied = total - cp.normal_impulse;
                unsettled |= applied.abs() > BOUNCE_SETTLED_SPEED * row.mass;
                pair.push(self, n, &row.turn, applied);
                self.points[i].normal_impulse = total;
            }
            if !unsettled {
                break;
            }
            backwards = !backwards;
        }
        pair.store(self, states);
    }
}

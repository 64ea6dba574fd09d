//! The normal rows of a contact batch, four contacts side by side: speculative points close
//! their gap, penetrating ones are pushed out softly when the pass is biased. The points of a
//! lane that is an impact (`ContactConstraint::impact`) are swept again, in the other order,
//! while its last sweep changed some point's normal speed by more than [`SETTLED_SPEED`], at
//! most [`MAX_SWEEPS`] times (why: `contact_normals.rs`). The other lanes keep what they
//! have, so each lane computes exactly its contact's scalar solve (the lanes move no common
//! body). The first sweep is the hot path; the rare further ones are out of line.

use super::*;
use crate::dynamics::solver::contact::{MAX_SWEEPS, SETTLED_SPEED};

/// What each sweep of one pass over a batch's normal rows reads: the batch, and what the
/// pass adds to it, taken once per pass.
struct NormalPass<'a> {
    batch: &'a ContactBatch,
    /// `(Δp_b − Δp_a)·n` per lane: the bodies' motion since the step's start along the normal.
    moved: Lanes,
    /// The normal turned back into A's and B's rotation since the step's start (see
    /// `ContactConstraint::solve_normals`).
    turned: [Vec3x4; 2],
    /// `mass_scale · bias_rate`, `mass_scale`, `impulse_scale` of the pass (the relax passes:
    /// no bias, rigid).
    softness: [Lanes; 3],
    inv_h: Lanes,
    most_push: Lanes,
    use_bias: bool,
}

/// One pass over the normal rows of `batch` (module docs). Inlined into the pass: called, it
/// kept the batch's velocities in memory across the call (10 % more instructions in the pass).
#[inline(always)]
pub(super) fn solve_normals(
    batch: &ContactBatch,
    points: &mut [PointX4],
    pair: &mut PairVelocities,
    states: &[BodyState],
    pass: &Pass,
) {
    let normals = NormalPass::new(batch, states, pass);
    // The velocities before this pass's impulses, for the impact speeds (see
    // `ConstraintPoint::relative_velocity`).
    let before = *pair;
    // One sweep solves a lone point's row exactly (balls need no second), and only impacts
    // may need more: the other batches do not even track what a sweep changed.
    if points.len() > 1 && batch.impacts.any() {
        let swept = normals.sweep::<false, true>(points, pair, &before, pass.flip, Lanes::ZERO);
        let unsettled = swept & batch.impacts;
        if unsettled.any() {
            normals.sweep_again(points, pair, &before, !pass.flip, unsettled);
        }
    } else {
        normals.sweep::<false, false>(points, pair, &before, pass.flip, Lanes::ZERO);
    }
}

/// `moved` with what `batch`'s rounded sides add to the separations when their bodies have
/// turned the normal to `turned` (`contact_normals::rolled`, four lanes at once; nothing for
/// lanes without rounding). Taken in every batch: behind a branch on whether any lane rolls,
/// the pass's code cost a pyramid of boxes, which never took it, 0.8 % of its instructions.
#[inline(always)]
fn rolled(batch: &ContactBatch, moved: Lanes, [na, nb]: [Vec3x4; 2]) -> Lanes {
    let (n, [rho_a, rho_b]) = (batch.normal, batch.rounding);
    moved + rho_a * n.dot(na - n) + rho_b * n.dot(nb - n)
}

impl<'a> NormalPass<'a> {
    /// Inlined, as [`solve_normals`]: returned through memory, it was read back by each sweep.
    #[inline(always)]
    fn new(batch: &'a ContactBatch, states: &[BodyState], pass: &Pass) -> Self {
        // A still side has not moved: the rest state's constants (the same bits as its states).
        let motion = |k: usize| {
            if batch.still[k] {
                return (Vec3x4::ZERO, Quatx4::IDENTITY);
            }
            // Written out, not `slots.map(..)` (see `Vec3x4::gather`).
            let at = |l: usize| &states[batch.bodies[k][l] as usize];
            let (s0, s1, s2, s3) = (at(0), at(1), at(2), at(3));
            (
                Vec3x4::gather([
                    s0.delta_position,
                    s1.delta_position,
                    s2.delta_position,
                    s3.delta_position,
                ]),
                Quatx4::gather([
                    s0.delta_rotation,
                    s1.delta_rotation,
                    s2.delta_rotation,
                    s3.delta_rotation,
                ]),
            )
        };
        let ((moved_a, dqa), (moved_b, dqb)) = (motion(0), motion(1));
        let n = batch.normal;
        let (zero, one) = (Lanes::ZERO, Lanes::ONE);
        let turned = [dqa.inverse_rotate(n), dqb.inverse_rotate(n)];
        let moved = (moved_b - moved_a).dot(n);
        Self {
            batch,
            moved: rolled(batch, moved, turned),
            turned,
            softness: if pass.use_bias {
                batch.softness
            } else {
                [zero, one, zero]
            },
            inv_h: Lanes::splat(pass.inv_h),
            most_push: Lanes::splat(-pass.max_push_out),
            use_bias: pass.use_bias,
        }
    }

    /// The sweeps after the first, for the impacts' lanes still `unsettled` (rare), each the
    /// other way round from the last.
    #[inline(never)]
    #[cold]
    fn sweep_again(
        &self,
        points: &mut [PointX4],
        pair: &mut PairVelocities,
        before: &PairVelocities,
        mut backwards: bool,
        mut unsettled: Lanes,
    ) {
        for _ in 1..MAX_SWEEPS {
            unsettled = self.sweep::<true, true>(points, pair, before, backwards, unsettled);
            if !unsettled.any() {
                break;
            }
            backwards = !backwards;
        }
    }

    /// One sweep over the points of every lane, or (`MASKED`) of the `active` lanes only (the
    /// others keep their impulses); the lanes in which it changed some point's normal speed by
    /// more than [`SETTLED_SPEED`] (when `TRACKED`; else none).
    #[inline(always)]
    fn sweep<const MASKED: bool, const TRACKED: bool>(
        &self,
        points: &mut [PointX4],
        pair: &mut PairVelocities,
        before: &PairVelocities,
        backwards: bool,
        active: Lanes,
    ) -> Lanes {
        let zero = Lanes::ZERO;
        let [bias_rate, soft_mass, soft_impulse] = self.softness;
        let (n, settled) = (self.batch.normal, Lanes::splat(SETTLED_SPEED));
        let mut unsettled = zero.simd_ne(zero);
        let count = points.len();
        for k in 0..count {
            let i = if backwards { count - 1 - k } else { k };
            let p = &mut points[i];
            let s = self.separation(p);
            let apart = s.simd_gt(zero);
            let push_out = if self.use_bias {
                (bias_rate * s).max(self.most_push)
            } else {
                zero
            };
            let bias = apart.select(s * self.inv_h, push_out);
            let mass_scale = apart.select(Lanes::ONE, soft_mass);
            let impulse_scale = apart.select(zero, soft_impulse);
            let row = &p.row(&p.normal_row, n);
            let vn = pair.along(n, row);
            let impulse = -row.mass * (mass_scale * vn + bias) - impulse_scale * p.normal_impulse;
            let total = (p.normal_impulse + impulse).max(zero);
            let total = if MASKED {
                active.select(total, p.normal_impulse)
            } else {
                total
            };
            let applied = total - p.normal_impulse;
            // `applied / mass` is the change of the point's normal speed.
            if TRACKED {
                unsettled |= applied.abs().simd_gt(settled * row.mass);
            }
            pair.push(self.batch.inverse_mass, n, &row.turn, applied);
            let first = p.max_normal_impulse.simd_eq(zero) & total.simd_gt(zero);
            if first.any() {
                let untouched = points
                    .iter()
                    .fold(first, |lanes, q| lanes & q.max_normal_impulse.simd_eq(zero));
                if untouched.any() {
                    self.time_impacts(points, before, untouched);
                }
            }
            let p = &mut points[i];
            p.normal_impulse = total;
            p.max_normal_impulse = p.max_normal_impulse.max(total);
        }
        unsettled
    }

    /// The current separation of point `p` in each lane (`ContactConstraint::separation`'s,
    /// four at a time).
    #[inline(always)]
    fn separation(&self, p: &PointX4) -> Lanes {
        let [na, nb] = self.turned;
        p.base_separation + self.moved + p.anchor_b.dot(nb) - p.anchor_a.dot(na)
    }

    /// The impact speeds of all the points of the `lanes` whose contact first pushes in the
    /// step, read from the velocities `before` the pass (`contact_normals.rs`, "One moment per
    /// impact"; the scalar `time_impact`).
    #[cold]
    #[inline(never)]
    fn time_impacts(&self, points: &mut [PointX4], before: &PairVelocities, lanes: Lanes) {
        let n = self.batch.normal;
        for q in points {
            let s = self.separation(q);
            let vn = before.along(n, &q.row(&q.normal_row, n));
            let speed = impact_speed(vn, s, self.batch.closing_acceleration);
            q.relative_velocity = lanes.select(speed, q.relative_velocity);
        }
    }
}

/// [`contact`](super::super::contact)'s `impact_speed` per lane: a speculative point
/// approaching at `vn` from `s` away meets the surface at `−√(vn² − 2 a s)`.
fn impact_speed(vn: Lanes, s: Lanes, closing: Lanes) -> Lanes {
    let zero = Lanes::ZERO;
    let squared = vn * vn - Lanes::splat(2.0) * closing * s;
    let faster =
        s.simd_gt(zero) & vn.simd_lt(zero) & squared.is_finite() & squared.simd_gt(vn * vn);
    faster.select(-squared.sqrt(), vn)
}

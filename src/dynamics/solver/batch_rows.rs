//! What a contact batch holds per lane, and the row arithmetic its passes run on it: the
//! vector forms of [`RowPart`], [`ConstraintPoint`] and [`PatchFriction`], one contact per SIMD
//! lane ([`batch`](super::batch) says how the batches are laid out and solved).
//!
//! A point is split in two: what every pass reads ([`PointX4`]: anchors, separation, the
//! normal row and its impulses) and what only the relax passes read ([`FrictionX4`]: the two
//! friction rows of friction per point). Neither keeps the rows' lever arms `r × d`: each pass
//! takes them from the point's anchors ([`PointX4::row`], the arithmetic of [`RowPart::new`],
//! so the same bits). The passes stream every batch from memory several times a substep, and
//! once a scene's batches outgrow the processor's cache that traffic, not the arithmetic, sets
//! the pace (a 3D pyramid of boxes, awake: 1.13× rapier's time at 204 boxes but 1.37× at
//! 1,015, where it ran 1.11× rapier's instructions, when a point took 816 bytes in one piece).

use super::contact::{ConstraintPoint, PointRow, RowPart, on_moving};
use super::contact_pair::SLIDING_FROM;
use super::lanes::{LANES, Lanes, PairVelocities, Vec3x4, set_lane};
use super::patch_friction::PatchFriction;
use crate::geometry::MAX_MANIFOLD_POINTS;
use glam::Vec3;

/// One row of four contacts with its lever arms ([`RowPart`] per lane): a patch's friction
/// rows as stored, a point's as [`PointX4::row`] completes them for a pass.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct RowX4 {
    arm: [Vec3x4; 2],
    pub turn: [Vec3x4; 2],
    pub mass: Lanes,
}

impl RowX4 {
    // Written out, not `[0, 1].map(..)`: the array map's drain stayed out of line.
    fn gather(rows: [&RowPart; LANES]) -> Self {
        let side = |part: fn(&RowPart) -> Vec3| Vec3x4::gather(rows.map(part));
        Self {
            arm: [side(|r| r.arm[0]), side(|r| r.arm[1])],
            turn: [side(|r| r.turn[0]), side(|r| r.turn[1])],
            mass: Lanes::new(rows.map(|r| r.mass)),
        }
    }
}

/// A point's row as a batch keeps it: [`RowX4`] without the lever arms.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct PointRowX4 {
    pub turn: [Vec3x4; 2],
    mass: Lanes,
}

impl PointRowX4 {
    /// Puts `row` in lane `lane` (a row rebuilt during a step, `turned_rows.rs`).
    pub fn set_lane(&mut self, lane: usize, row: &PointRow) {
        self.turn[0].set_lane(lane, row.turn[0]);
        self.turn[1].set_lane(lane, row.turn[1]);
        set_lane(&mut self.mass, lane, row.mass);
    }

    fn gather(rows: [&PointRow; LANES]) -> Self {
        let side = |part: fn(&PointRow) -> Vec3| Vec3x4::gather(rows.map(part));
        Self {
            turn: [side(|r| r.turn[0]), side(|r| r.turn[1])],
            mass: Lanes::new(rows.map(|r| r.mass)),
        }
    }
}

/// The `k`-th point of four contacts, what every pass reads of it ([`ConstraintPoint`] per
/// lane, less the friction rows).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct PointX4 {
    pub anchor_a: Vec3x4,
    pub anchor_b: Vec3x4,
    pub base_separation: Lanes,
    pub normal_row: PointRowX4,
    pub normal_impulse: Lanes,
    pub max_normal_impulse: Lanes,
    pub relative_velocity: Lanes,
}

impl PointX4 {
    /// The points of four lanes, whose bodies are still as `still` says per lane (A, B): a
    /// still body's anchor is taken as zero ([`on_moving`]).
    pub fn gather(points: [&ConstraintPoint; LANES], still: [[bool; 2]; LANES]) -> Self {
        let each = |f: fn(&ConstraintPoint) -> f32| Lanes::new(points.map(f));
        let anchors = |side: usize, r: fn(&ConstraintPoint) -> Vec3| {
            // Written out, not `array::from_fn`, which may stay out of line (see
            // `Vec3x4::gather`).
            let at = |l: usize| on_moving(still[l][side], r(points[l]));
            Vec3x4::gather([at(0), at(1), at(2), at(3)])
        };
        Self {
            anchor_a: anchors(0, |p| p.anchor_a),
            anchor_b: anchors(1, |p| p.anchor_b),
            base_separation: each(|p| p.base_separation),
            normal_row: PointRowX4::gather(points.map(|p| &p.normal_row)),
            normal_impulse: each(|p| p.normal_impulse),
            max_normal_impulse: each(|p| p.max_normal_impulse),
            relative_velocity: each(|p| p.relative_velocity),
        }
    }

    /// `row` (along `dir`) with its lever arms `r_a × d`, `r_b × d`.
    #[inline(always)]
    pub fn row(&self, row: &PointRowX4, dir: Vec3x4) -> RowX4 {
        RowX4 {
            arm: [self.anchor_a.cross(dir), self.anchor_b.cross(dir)],
            turn: row.turn,
            mass: row.mass,
        }
    }

    /// Writes lane `lane`'s normal impulses and approach speed into `point`.
    pub fn scatter(&self, lane: usize, point: &mut ConstraintPoint) {
        let at = |v: &Lanes| v.as_array()[lane];
        point.normal_impulse = at(&self.normal_impulse);
        point.max_normal_impulse = at(&self.max_normal_impulse);
        point.relative_velocity = at(&self.relative_velocity);
    }
}

/// The friction rows of the `k`-th point of four contacts (friction per point), read by the
/// relax passes and the warm start only.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct FrictionX4 {
    pub rows: [PointRowX4; 2],
    /// [`ConstraintPoint::tangent_drift`].
    pub drift: [Lanes; 2],
    pub impulse: [Lanes; 2],
}

impl FrictionX4 {
    pub fn gather(points: [&ConstraintPoint; LANES]) -> Self {
        let each = |f: fn(&ConstraintPoint) -> f32| Lanes::new(points.map(f));
        Self {
            rows: [
                PointRowX4::gather(points.map(|p| &p.tangent_rows[0])),
                PointRowX4::gather(points.map(|p| &p.tangent_rows[1])),
            ],
            drift: [each(|p| p.tangent_drift[0]), each(|p| p.tangent_drift[1])],
            impulse: [
                each(|p| p.tangent_impulse[0]),
                each(|p| p.tangent_impulse[1]),
            ],
        }
    }

    /// Writes lane `lane`'s friction impulses into `point`.
    pub fn scatter(&self, lane: usize, point: &mut ConstraintPoint) {
        point.tangent_impulse = self.impulse.each_ref().map(|v| v.as_array()[lane]);
    }
}

/// Four contacts' [`PatchFriction`] (zero rows in lanes without one).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct PatchX4 {
    pub tangent_rows: [RowX4; 2],
    pub twist_turn: [Vec3x4; 2],
    pub twist_mass: Lanes,
    pub arms: [Lanes; MAX_MANIFOLD_POINTS],
    pub tangent_drift: [Lanes; 2],
    pub tangent_impulse: [Lanes; 2],
    pub twist_impulse: Lanes,
}

impl PatchX4 {
    pub fn gather(patches: [&PatchFriction; LANES]) -> Self {
        let each = |f: fn(&PatchFriction) -> f32| Lanes::new(patches.map(f));
        let side = |f: fn(&PatchFriction) -> Vec3| Vec3x4::gather(patches.map(f));
        Self {
            tangent_rows: [
                RowX4::gather(patches.map(|p| &p.tangent_rows[0])),
                RowX4::gather(patches.map(|p| &p.tangent_rows[1])),
            ],
            twist_turn: [side(|p| p.twist_turn[0]), side(|p| p.twist_turn[1])],
            twist_mass: each(|p| p.twist_mass),
            arms: std::array::from_fn(|k| Lanes::new(patches.map(|p| p.arms[k]))),
            tangent_drift: [each(|p| p.tangent_drift[0]), each(|p| p.tangent_drift[1])],
            tangent_impulse: [
                each(|p| p.tangent_impulse[0]),
                each(|p| p.tangent_impulse[1]),
            ],
            twist_impulse: each(|p| p.twist_impulse),
        }
    }

    /// Writes lane `lane`'s impulses into `patch`.
    pub fn scatter(&self, lane: usize, patch: &mut PatchFriction) {
        let at = |v: &Lanes| v.as_array()[lane];
        patch.tangent_impulse = self.tangent_impulse.each_ref().map(at);
        patch.twist_impulse = at(&self.twist_impulse);
    }
}

/// What a contact row reads of its bodies' velocities and adds to them.
impl PairVelocities {
    /// The rate of a row: `d·(v_b − v_a) + (r_b × d)·ω_b − (r_a × d)·ω_a`.
    pub(super) fn along(&self, dir: Vec3x4, row: &RowX4) -> Lanes {
        dir.dot(self.vb - self.va) + row.arm[1].dot(self.wb) - row.arm[0].dot(self.wa)
    }

    /// An impulse `λ d` on B at its anchor, `−λ d` on A, through the row's angular velocity
    /// changes per unit impulse `turn` (the lever arms are not needed).
    pub(super) fn push(
        &mut self,
        inverse_mass: [Lanes; 2],
        dir: Vec3x4,
        turn: &[Vec3x4; 2],
        lambda: Lanes,
    ) {
        self.va = self.va - dir * (lambda * inverse_mass[0]);
        self.wa = self.wa - turn[0] * lambda;
        self.vb = self.vb + dir * (lambda * inverse_mass[1]);
        self.wb = self.wb + turn[1] * lambda;
    }

    /// An angular impulse `λ n` on B, `−λ n` on A (a patch's twist row).
    pub(super) fn twist(&mut self, patch: &PatchX4, lambda: Lanes) {
        self.wa = self.wa - patch.twist_turn[0] * lambda;
        self.wb = self.wb + patch.twist_turn[1] * lambda;
    }

    /// Two tangent rows clamped together to the disc `|λ| ≤ limit`, each solving
    /// `J V + share · drift = 0` (`J V = 0`, the drift unread, unless `DRIFT`), as the scalar
    /// rows: the new accumulated impulses from the `old` ones.
    #[inline(always)]
    pub(super) fn solve_disc<const DRIFT: bool>(
        &mut self,
        [r0, r1]: &[RowX4; 2],
        [t0, t1]: [Vec3x4; 2],
        ([old0, old1], [drift0, drift1], share): ([Lanes; 2], [Lanes; 2], Lanes),
        (limit, inverse_mass): (Lanes, [Lanes; 2]),
    ) -> [Lanes; 2] {
        let (zero, one) = (Lanes::ZERO, Lanes::ONE);
        let (mut v0, mut v1) = (self.along(t0, r0), self.along(t1, r1));
        if DRIFT {
            (v0, v1) = (v0 + drift0 * share, v1 + drift1 * share);
        }
        let w0 = old0 - r0.mass * v0;
        let w1 = old1 - r1.mass * v1;
        let length = (w0 * w0 + w1 * w1).sqrt();
        let clamped = length.simd_gt(limit) & length.simd_gt(zero);
        // Sliding, the impulse opposes the slip (the scalar rows' `Pair::solve_disc` says
        // why and how); only clamped lanes take it, so a batch with none skips it.
        let (w0, w1, length) = if clamped.any() {
            sliding(
                [w0, w1],
                length,
                clamped,
                ([old0, old1], [v0, v1]),
                (limit, [r0, r1]),
            )
        } else {
            (w0, w1, length)
        };
        let scale = clamped.select(limit / length, one);
        let (new0, new1) = (w0 * scale, w1 * scale);
        self.push(inverse_mass, t0, &r0.turn, new0 - old0);
        self.push(inverse_mass, t1, &r1.turn, new1 - old1);
        [new0, new1]
    }
}

/// The impulse of clamped lanes that slide, before the clamp (see `Pair::solve_disc`): from
/// the rows' own masses `w` towards `old − m̄ v` as the lane asks for 4–8 times its limit.
/// Where nothing is asked and there is no limit, the blend is 0/0, and such a lane is not
/// clamped: the mask keeps `w` there.
#[inline(always)]
fn sliding(
    [w0, w1]: [Lanes; 2],
    length: Lanes,
    clamped: Lanes,
    ([old0, old1], [v0, v1]): ([Lanes; 2], [Lanes; 2]),
    (limit, [r0, r1]): (Lanes, [&RowX4; 2]),
) -> (Lanes, Lanes, Lanes) {
    let (zero, one) = (Lanes::ZERO, Lanes::ONE);
    let mean = (r0.mass + r1.mass) * Lanes::splat(0.5);
    let from = Lanes::splat(SLIDING_FROM);
    let slid = ((length / limit - from) / from).min(one).max(zero);
    let s0 = w0 + slid * (old0 - mean * v0 - w0);
    let s1 = w1 + slid * (old1 - mean * v1 - w1);
    let slide = (s0 * s0 + s1 * s1).sqrt();
    let slides = clamped & slide.simd_gt(zero);
    (
        slides.select(s0, w0),
        slides.select(s1, w1),
        slides.select(slide, length),
    )
}

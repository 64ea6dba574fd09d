//! A constraint row's parts that stay fixed over a step: the lever arms `r × d`, the angular
//! velocity changes per unit impulse `I⁻¹ (r × d)` and the effective mass `1/K` (Jolt's
//! `AxisConstraintPart`, Box2D's per-point masses); the derivation is in
//! [`contact`](super::contact)'s module docs.
//!
//! A contact point keeps its rows without the lever arms ([`PointRow`]) and takes them from its
//! anchors when a pass needs them: two cross products against a third less to read. The passes
//! stream the step's contacts from memory many times a substep, and on large scenes that
//! traffic, not the arithmetic, sets their pace.

use super::body::BodyParams;
use glam::Vec3;

/// What one row of one point needs in the passes (Jolt's `AxisConstraintPart`, Box2D's
/// per-point masses): for a direction `d` and anchors `r_a`, `r_b`, the lever arms `r × d`, the
/// angular velocity changes per unit impulse `I⁻¹ (r × d)`, and `1/K`. Precomputed once per
/// step, so a pass does no matrix product.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RowPart {
    /// `r_a × d`, `r_b × d`.
    pub arm: [Vec3; 2],
    /// `I_a⁻¹ (r_a × d)`, `I_b⁻¹ (r_b × d)`.
    pub turn: [Vec3; 2],
    /// `1/K`, `K = d·W_a d + d·W_b d + (r_a×d)·I_a⁻¹(r_a×d) + (r_b×d)·I_b⁻¹(r_b×d)` with
    /// `W = diag(1/m per axis)` (`1/m_a + 1/m_b` for unit `d` without locks; 0 if immovable).
    pub mass: f32,
}

impl RowPart {
    /// The row along `dir` at anchors `ra`, `rb`; `linear` is its translational part
    /// `d·W_a d + d·W_b d` (the same for every point of a contact, so computed once).
    #[inline]
    pub(super) fn new(
        pa: &BodyParams,
        pb: &BodyParams,
        ra: Vec3,
        rb: Vec3,
        (dir, linear): (Vec3, f32),
    ) -> Self {
        let arm = [ra.cross(dir), rb.cross(dir)];
        let turn = [pa.inverse_inertia * arm[0], pb.inverse_inertia * arm[1]];
        let k = linear + arm[0].dot(turn[0]) + arm[1].dot(turn[1]);
        let mass = if k > 0.0 && k.is_finite() {
            1.0 / k
        } else {
            0.0
        };
        Self { arm, turn, mass }
    }
}

/// A point's row as a contact keeps it: [`RowPart`] without the lever arms (`From<RowPart>`),
/// which [`Self::with_arms`] takes from the point's anchors (the same arithmetic as
/// `RowPart::new`, so the same bits).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointRow {
    /// `I_a⁻¹ (r_a × d)`, `I_b⁻¹ (r_b × d)`.
    pub turn: [Vec3; 2],
    /// `1/K` ([`RowPart::mass`]).
    pub mass: f32,
}

impl From<RowPart> for PointRow {
    /// The row less its lever arms.
    #[inline]
    fn from(RowPart { turn, mass, .. }: RowPart) -> Self {
        Self { turn, mass }
    }
}

impl PointRow {
    /// The whole row along `dir` for anchors `ra`, `rb`.
    #[inline(always)]
    pub fn with_arms(&self, ra: Vec3, rb: Vec3, dir: Vec3) -> RowPart {
        RowPart {
            arm: [ra.cross(dir), rb.cross(dir)],
            turn: self.turn,
            mass: self.mass,
        }
    }
}

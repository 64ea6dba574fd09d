//! The separating axis search of [`contact_cuboid_cuboid`](super::contact_cuboid_cuboid): the
//! 15 candidate axes of two oriented boxes (Gottschalk, Lin & Manocha 1996, "OBBTree"), the
//! shallowest of each kind, and the biased choice among them (steps 1–3 of that function's
//! module docs). Kept apart from the contact points built on the chosen axis.
//!
//! - Two convex polyhedra are disjoint iff their projections are disjoint on some face normal
//!   of either or on some cross product of an edge of each: 3 + 3 face normals and 3 × 3 edge
//!   pairs for boxes. The overlap on an axis is the penetration along it.
//! - Nearly parallel edges give a cross product whose direction is rounding noise: it is
//!   skipped, parallel edges being covered by the face normals.
//! - An edge axis wins only if clearly shallower than the best face, and B's face only if
//!   clearly shallower than A's (ODE's 5% fudge factor, Box2D's tolerances), so that resting
//!   boxes do not flicker between nearly equal axes.

use super::prefer_towards_fallback;
use glam::{Mat3, Vec3};

/// Edge-pair axes with `|e_a × e_b|² = sin²(angle)` below this are skipped (step 2 above).
/// Skipping loses at most about `sin(angle) × box size` of separation, here `1e-6` of the size,
/// below f32 resolution; any larger cross product, however noisy its direction, is still a
/// valid unit axis to project on, so testing it can never report a false separation.
const EDGE_AXIS_MIN_SIN2: f32 = 1e-12;

/// B's best face replaces A's only if its depth is below `FACE_SWITCH_REL × A's - tolerance`.
const FACE_SWITCH_REL: f32 = 0.98;

/// The best edge axis replaces the face axis only if its depth is below
/// `EDGE_SWITCH_REL × face depth - tolerance` (ODE's fudge factor 1.05 ≈ 1/0.95).
const EDGE_SWITCH_REL: f32 = 0.95;

/// The absolute part of both switch tolerances, as a fraction of the smaller box's largest
/// half extent (so that it scales with the scene): near-zero depths in resting contact must not
/// hand the choice to rounding noise.
const SWITCH_ABS_FRACTION: f32 = 1e-3;

/// A box seen from A's frame: centre, axes as the columns of `axes`, half extents.
#[derive(Clone, Copy, Debug)]
pub(super) struct FramedBox {
    pub(super) center: Vec3,
    pub(super) axes: Mat3,
    pub(super) half: Vec3,
}

/// Which features span a candidate axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Feature {
    /// The face normal of A along its local axis `i`.
    FaceOfA(usize),
    /// The face normal of B along its local axis `j`.
    FaceOfB(usize),
    /// The cross product of A's edge along axis `i` and B's edge along axis `j`.
    Edges(usize, usize),
}

/// A candidate separating axis: unit `normal` from A to B (A's frame), the overlap `depth` of
/// the two projections on it, and `up`, the normal's component along [`FALLBACK_NORMAL`](super::FALLBACK_NORMAL).
#[derive(Clone, Copy, Debug)]
pub(super) struct Axis {
    pub(super) normal: Vec3,
    pub(super) depth: f32,
    pub(super) up: f32,
    pub(super) feature: Feature,
}

impl Axis {
    /// The axis `direction` (unit), oriented from A to B given `along`, the projection of B's
    /// centre on it; a zero projection orients it towards `up` (both in A's frame).
    fn oriented(direction: Vec3, along: f32, up: Vec3, depth: f32, feature: Feature) -> Self {
        let up_component = direction.dot(up);
        let flip = along < 0.0 || (along == 0.0 && up_component < 0.0);
        let sign = if flip { -1.0 } else { 1.0 };
        Self {
            normal: direction * sign,
            depth,
            up: up_component * sign,
            feature,
        }
    }

    /// Shallower wins; equal depths go to the normal closer to [`FALLBACK_NORMAL`](super::FALLBACK_NORMAL).
    fn beats(&self, other: &Self) -> bool {
        self.depth < other.depth
            || (self.depth == other.depth && prefer_towards_fallback(self.up, other.up))
    }
}

/// The shallowest axis of each kind, or `None` from [`least_penetration_axes`] when some axis
/// separates the boxes.
#[derive(Clone, Copy, Debug)]
pub(super) struct BestAxes {
    pub(super) face_a: Axis,
    pub(super) face_b: Axis,
    pub(super) edge: Option<Axis>,
}

/// The 15 axes of the separating axis test for `a` (at A's origin, axis-aligned) and `b`; `None`
/// as soon as one separates them (a negative overlap: touching, overlap zero, is a contact).
pub(super) fn least_penetration_axes(a: &FramedBox, b: &FramedBox, up: Vec3) -> Option<BestAxes> {
    let r = b.axes;
    let abs_r = Mat3::from_cols(r.x_axis.abs(), r.y_axis.abs(), r.z_axis.abs());
    let t = b.center;

    let mut face_a: Option<Axis> = None;
    for i in 0..3 {
        let depth = a.half[i] + abs_r.row(i).dot(b.half) - t[i].abs();
        if depth < 0.0 {
            return None;
        }
        let axis = Axis::oriented(Vec3::AXES[i], t[i], up, depth, Feature::FaceOfA(i));
        keep_better(&mut face_a, axis);
    }

    let mut face_b: Option<Axis> = None;
    for j in 0..3 {
        let along = t.dot(r.col(j));
        let depth = abs_r.col(j).dot(a.half) + b.half[j] - along.abs();
        if depth < 0.0 {
            return None;
        }
        let axis = Axis::oriented(r.col(j), along, up, depth, Feature::FaceOfB(j));
        keep_better(&mut face_b, axis);
    }

    let mut edge: Option<Axis> = None;
    let r_t = r.transpose();
    for i in 0..3 {
        for j in 0..3 {
            let cross = Vec3::AXES[i].cross(r.col(j));
            let len2 = cross.length_squared();
            // Also skips a NaN length.
            if len2 < EDGE_AXIS_MIN_SIN2 || len2.is_nan() {
                continue;
            }
            let l = cross / len2.sqrt();
            let along = t.dot(l);
            let depth = l.abs().dot(a.half) + (r_t * l).abs().dot(b.half) - along.abs();
            if depth < 0.0 {
                return None;
            }
            keep_better(
                &mut edge,
                Axis::oriented(l, along, up, depth, Feature::Edges(i, j)),
            );
        }
    }

    // Three face axes of each box were offered above, so both options hold a value; the
    // fallbacks only keep this total.
    Some(BestAxes {
        face_a: face_a.unwrap_or(Axis::oriented(Vec3::X, t.x, up, 0.0, Feature::FaceOfA(0))),
        face_b: face_b.unwrap_or(Axis::oriented(r.x_axis, 0.0, up, 0.0, Feature::FaceOfB(0))),
        edge,
    })
}

/// Replaces `best` by `candidate` when there is none yet or the candidate beats it.
fn keep_better(best: &mut Option<Axis>, candidate: Axis) {
    if best.is_none_or(|b| candidate.beats(&b)) {
        *best = Some(candidate);
    }
}

/// The axis to build contacts on: A's best face, unless B's face or an edge axis is clearly
/// shallower (step 3 of the module docs).
pub(super) fn choose_axis(best: &BestAxes, half_a: Vec3, half_b: Vec3) -> Axis {
    let tolerance = SWITCH_ABS_FRACTION * half_a.max_element().min(half_b.max_element());
    let mut chosen = best.face_a;
    if best.face_b.depth < FACE_SWITCH_REL * chosen.depth - tolerance {
        chosen = best.face_b;
    }
    match best.edge {
        Some(edge) if edge.depth < EDGE_SWITCH_REL * chosen.depth - tolerance => edge,
        _ => chosen,
    }
}

//! The building blocks of the exact queries: a point moving along `m + t·d`, `t ∈ [0, 1]`,
//! entering a ball, a finite cylinder's side, or a box of slabs (Ericson 2005, *Real-Time
//! Collision Detection* §5.3.2, §5.3.3, §5.3.7). A sphere sweep against an obstacle is the sweep
//! of its centre against the obstacle inflated by the radius, and the inflated shapes are unions
//! of these pieces.
//!
//! Each piece reports its **first entry while approaching**: a point already inside a piece and
//! moving inward enters at `t = 0` (it can only be there by rounding, since callers test the start
//! with the exact static test first), a point inside and moving out never enters (the piece is
//! convex, so it cannot come back).

use glam::Vec3;

/// An entry into a piece: when, and the piece's outward unit normal there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PieceHit {
    pub t: f32,
    pub normal: Vec3,
    /// True for a flat face (of a triangle or a box), whose normal is the surface's own; false
    /// for a cylinder or a ball, whose normal turns with the hit point.
    pub on_face: bool,
}

/// Which curved piece of an inflated shape was entered, with what its normal needs. Queries
/// compare entry *times* only and compute the one normal of the winner at the end, which saves a
/// square root and a division per losing piece. (Flat faces need no comparison: an entry through
/// one is always the first, see the queries.)
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Piece {
    /// The side of the cylinder around the segment from `start` to `start + edge`.
    Edge { start: Vec3, edge: Vec3 },
    /// The ball around a vertex.
    Vertex(Vec3),
}

/// The earliest entry found so far over a shape's pieces.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Earliest {
    /// Entries after this are not wanted (the caller's bound, then the best entry's time).
    pub t_max: f32,
    pub best: Option<(f32, Piece)>,
}

impl Earliest {
    /// Nothing found yet; only entries at or before `t_max` count.
    pub fn before(t_max: f32) -> Self {
        Self { t_max, best: None }
    }

    /// Keeps the entry if it is strictly earlier than the best (ties keep the incumbent: a fixed
    /// order of pieces makes the result deterministic).
    #[inline]
    pub fn consider(&mut self, t: Option<f32>, piece: Piece) {
        if let Some(t) = t {
            let earlier = self.best.is_none_or(|(best, _)| t < best);
            if earlier && t <= self.t_max {
                self.t_max = t;
                self.best = Some((t, piece));
            }
        }
    }

    /// The winner with its normal, for the point `origin + t·displacement` (`fallback` where
    /// the piece defines none: a zero radius).
    pub fn hit(
        &self,
        origin: Vec3,
        displacement: Vec3,
        fallback: impl FnOnce() -> Vec3,
    ) -> Option<PieceHit> {
        let (t, piece) = self.best?;
        let at = origin + displacement * t;
        let normal = match piece {
            Piece::Edge { start, edge } => {
                let m = at - start;
                unit_or(m - edge * (m.dot(edge) / edge.length_squared()), fallback)
            }
            Piece::Vertex(v) => unit_or(at - v, fallback),
        };
        Some(PieceHit {
            t,
            normal,
            on_face: false,
        })
    }
}

/// `v / |v|`, or `fallback()` for a zero (or non-finite) `v`. Vectors too short or too long for
/// an accurate `f32` square length (components below about 1e-15 or above 1e18, where the
/// squared length is subnormal or overflows) are normalised in `f64`, so the result is always
/// unit instead of off by percents.
#[inline]
pub(crate) fn unit_or(v: Vec3, fallback: impl FnOnce() -> Vec3) -> Vec3 {
    let length_squared = v.length_squared();
    if (1e-30..=1e36).contains(&length_squared) {
        return v / length_squared.sqrt();
    }
    v.as_dvec3()
        .try_normalize()
        .map_or_else(fallback, |u| u.as_vec3())
}

/// First entry time of `m + t·d` into the ball `|x| <= radius`.
///
/// Solves `|m + t d|² = R²` for its smaller root in the cancellation-free forms
/// `disc = |d|²R² − |m × d|²` and `t = c / (−b + √disc)` with `b = m·d`, `c = |m|² − R²`
/// (Ericson §5.3.2, the "numerically robust" variant): no division by `|d|²`, so a tiny
/// displacement is as accurate as a large one.
#[inline]
pub(crate) fn ball_entry(m: Vec3, d: Vec3, radius: f32) -> Option<f32> {
    let b = m.dot(d);
    // Not approaching the centre (or NaN): never enters a ball it is outside of, and leaves
    // one it is inside of.
    if b.is_nan() || b >= 0.0 {
        return None;
    }
    let c = m.length_squared() - radius * radius;
    if c <= 0.0 {
        return Some(0.0);
    }
    let disc = d.length_squared() * (radius * radius) - m.cross(d).length_squared();
    if disc.is_nan() || disc < 0.0 {
        return None;
    }
    // b < 0, so the denominator is positive; c > 0, so t > 0.
    let t = c / (disc.sqrt() - b);
    (t <= 1.0).then_some(t)
}

/// First entry time of `m + t·d` through the side of the cylinder of `radius` around the
/// segment from the origin to `edge` (non-zero).
///
/// The side is the infinite cylinder kept where the point's projection falls on the segment:
/// entries through the end discs are left to the balls at the segment's ends, which contain the
/// discs and are entered no later.
#[inline]
pub(crate) fn cylinder_entry(m: Vec3, d: Vec3, edge: Vec3, radius: f32) -> Option<f32> {
    let inv_len2 = 1.0 / edge.length_squared();
    let m_perp = m - edge * (m.dot(edge) * inv_len2);
    let d_perp = d - edge * (d.dot(edge) * inv_len2);
    let t = ball_entry(m_perp, d_perp, radius)?;
    let along = (m + d * t).dot(edge) * inv_len2;
    (0.0..=1.0).contains(&along).then_some(t)
}

/// The part of the segment `o + t·d`, `t ∈ [0, 1]`, inside the box `[-half, half]`: the
/// interval `[t_in, t_out]` and, when the segment enters through a face at `t_in > 0`, that
/// face's `(axis, outward sign)` (Kay and Kajiya 1986 slabs; Ericson §5.3.3).
///
/// Divides by each non-zero `d[i]` rather than multiplying by a precomputed inverse, so that a
/// point on a slab's plane with a tiny `d[i]` gives `0`, never `0 × ∞ = NaN`.
pub(crate) fn segment_in_box(o: Vec3, d: Vec3, half: Vec3) -> Option<BoxSpan> {
    let (mut t_in, mut t_out, mut entry) = (0.0f32, 1.0f32, None);
    for i in 0..3 {
        if d[i] == 0.0 {
            if o[i].abs() > half[i] {
                return None;
            }
            continue;
        }
        let to_low = (-half[i] - o[i]) / d[i];
        let to_high = (half[i] - o[i]) / d[i];
        // Moving up enters through the low face (outward normal −e_i), moving down the high.
        let (near, far, sign) = if d[i] > 0.0 {
            (to_low, to_high, -1.0)
        } else {
            (to_high, to_low, 1.0)
        };
        if near > t_in {
            t_in = near;
            entry = Some((i, sign));
        }
        t_out = t_out.min(far);
        if t_in.is_nan() || t_out.is_nan() || t_in > t_out {
            return None;
        }
    }
    Some(BoxSpan { t_in, t_out, entry })
}

/// The result of [`segment_in_box`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BoxSpan {
    pub t_in: f32,
    pub t_out: f32,
    /// `(axis, ±1)` of the face entered at `t_in`; `None` when the segment starts inside.
    pub entry: Option<(usize, f32)>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ball_entry_head_on_tangent_inside_and_leaving() {
        // Head-on: from x = -5 by +10 into the unit ball: enters at x = -1, t = 0.4.
        let t = ball_entry(Vec3::new(-5.0, 0.0, 0.0), Vec3::X * 10.0, 1.0).unwrap();
        assert!((t - 0.4).abs() < 1e-7);
        // Exactly tangent, with exact arithmetic: disc = 100·4 − |(−5,2,0)×(10,0,0)|² = 0.
        assert_eq!(
            ball_entry(Vec3::new(-5.0, 2.0, 0.0), Vec3::X * 10.0, 2.0),
            Some(0.5)
        );
        let miss = ball_entry(Vec3::new(-5.0, 2.0f32.next_up(), 0.0), Vec3::X * 10.0, 2.0);
        assert!(miss.is_none());
        // Inside and moving in: t = 0; inside and moving out, or still: never.
        assert_eq!(ball_entry(Vec3::X * 0.5, -Vec3::X, 1.0), Some(0.0));
        assert!(ball_entry(Vec3::X * 0.5, Vec3::X, 1.0).is_none());
        assert!(ball_entry(Vec3::X * 5.0, Vec3::ZERO, 1.0).is_none());
        // Too short a step, and exactly long enough.
        assert!(ball_entry(Vec3::new(-5.0, 0.0, 0.0), Vec3::X * 3.9, 1.0).is_none());
        assert_eq!(
            ball_entry(Vec3::new(-5.0, 0.0, 0.0), Vec3::X * 4.0, 1.0),
            Some(1.0)
        );
        // A zero radius is a point: hit only dead on.
        assert_eq!(
            ball_entry(Vec3::new(-2.0, 0.0, 0.0), Vec3::X * 4.0, 0.0),
            Some(0.5)
        );
        assert!(ball_entry(Vec3::new(-2.0, 1e-3, 0.0), Vec3::X * 4.0, 0.0).is_none());
    }

    #[test]
    fn normals_of_the_winning_piece_and_the_earliest_rule() {
        let mut earliest = Earliest::before(1.0);
        earliest.consider(Some(0.5), Piece::Vertex(Vec3::ZERO));
        earliest.consider(Some(0.5), Piece::Vertex(Vec3::Y));
        earliest.consider(None, Piece::Vertex(Vec3::Y));
        earliest.consider(Some(0.7), Piece::Vertex(Vec3::Y));
        let hit = earliest
            .hit(Vec3::new(-2.0, 0.0, 0.0), Vec3::X * 2.0, || Vec3::Z)
            .unwrap();
        assert_eq!((hit.t, hit.normal, hit.on_face), (0.5, -Vec3::X, false));
        // The edge's normal is perpendicular to it; a point on the axis takes the fallback.
        let edge = Piece::Edge {
            start: Vec3::ZERO,
            edge: Vec3::Z * 2.0,
        };
        let mut on_edge = Earliest::before(1.0);
        on_edge.consider(Some(0.25), edge);
        let hit = on_edge
            .hit(Vec3::new(1.0, 0.0, 0.5), Vec3::ZERO, || Vec3::Z)
            .unwrap();
        assert_eq!(hit.normal, Vec3::X);
        let hit = on_edge
            .hit(Vec3::new(0.0, 0.0, 0.5), Vec3::ZERO, || -Vec3::Y)
            .unwrap();
        assert_eq!(hit.normal, -Vec3::Y);
        // Subnormal offsets still give unit normals.
        assert_eq!(unit_or(Vec3::new(1e-22, 0.0, 0.0), || Vec3::Z), Vec3::X);
        assert!(unit_or(Vec3::new(3e-20, -4e-20, 0.0), || Vec3::Z).is_normalized());
        assert!(unit_or(Vec3::new(3e30, 4e30, 1e30), || Vec3::Z).is_normalized());
        assert_eq!(unit_or(Vec3::ZERO, || Vec3::Z), Vec3::Z);
        // Entries later than the bound are dropped.
        let mut bounded = Earliest::before(0.3);
        bounded.consider(Some(0.4), Piece::Vertex(Vec3::Y));
        assert!(bounded.best.is_none());
    }

    #[test]
    fn cylinder_side_only_within_the_segment() {
        // Axis along z from 0 to 2, radius 1; a point coming along -x at height 1.
        let edge = Vec3::Z * 2.0;
        let t = cylinder_entry(Vec3::new(3.0, 0.0, 1.0), Vec3::X * -4.0, edge, 1.0).unwrap();
        assert!((t - 0.5).abs() < 1e-7);
        // Same at height 2.5: above the segment, the side is not hit (the end ball would be).
        assert!(cylinder_entry(Vec3::new(3.0, 0.0, 2.5), Vec3::X * -4.0, edge, 1.0).is_none());
        // Moving along the axis: never enters the side.
        assert!(cylinder_entry(Vec3::new(3.0, 0.0, -1.0), Vec3::Z * 4.0, edge, 1.0).is_none());
    }

    #[test]
    fn box_span_entry_face_and_starting_inside() {
        let half = Vec3::ONE;
        let span = segment_in_box(Vec3::new(-3.0, 0.5, 0.0), Vec3::X * 4.0, half).unwrap();
        assert_eq!(
            (span.t_in, span.t_out, span.entry),
            (0.5, 1.0, Some((0, -1.0)))
        );
        let inside = segment_in_box(Vec3::ZERO, Vec3::Y * 4.0, half).unwrap();
        assert_eq!((inside.t_in, inside.t_out, inside.entry), (0.0, 0.25, None));
        assert!(segment_in_box(Vec3::new(-3.0, 1.5, 0.0), Vec3::X * 4.0, half).is_none());
        // On a face's plane with a subnormal component: no NaN.
        let grazing = segment_in_box(Vec3::new(-3.0, 1.0, 0.0), Vec3::new(4.0, -1e-40, 0.0), half);
        assert!(grazing.is_some_and(|s| s.t_in == 0.5));
    }
}

//! Convex–convex contact for the shapes without a closed form (cylinders, ellipsoids, hulls, and
//! anything paired with one): GJK/EPA give the normal and the deepest points
//! ([`crate::geometry::convex`]), and the manifold is clipped from the two supporting features
//! along that normal (Gregorius, "Robust contact creation for physics simulations", GDC 2015;
//! Jolt's `ManifoldBetweenTwoFaces`): the better aligned face is the reference, the other
//! feature is clipped to the reference's side planes, and each clipped point keeps its own depth
//! to the reference plane, measured along the normal. The normal stays EPA's (for polytopes it
//! is an exact face normal of `A − B` once EPA converges), so the deepest point's depth is EPA's.
//!
//! With a `margin`, pairs still apart by up to it report their gap as a negative depth (the
//! speculative contacts of `speculative.rs`), exactly: GJK measures the gap directly.
//!
//! Feature ids: a clipped point is named by the two features (A's, then B's, by their numbers
//! within their shapes) and its clip tag (`polygon_clip.rs`) with each line renumbered by the
//! shape it belongs to, so that it keeps its name when the reference passes from one face to
//! the other (two parallel faces tie, and a spinning plate on a hull slab swapped them from
//! step to step: its warm start was lost and it sank 0.13 mm, 0.02 µm once named this way);
//! the ends of two parallel lines by which end; the deepest point by being it.

use super::manifold_reduction::spread_points;
use super::polygon_clip::{ClipPolygon, FIRST_PLANE};
use crate::geometry::convex::SignedDistance;
use crate::geometry::convex::core_distance_within;
use crate::geometry::convex::support::{ConvexPart, Feature, MAX_FEATURE_POINTS};
use crate::geometry::{ContactManifold, ContactPoint, FeatureId, HalfSpace, Isometry, Shape};
use glam::Vec3;

/// A face serves as the reference only when its normal is this close to the contact normal
/// (cosine, ~11°): a steeper face would measure depths along a tilted plane.
const REFERENCE_COSINE: f32 = 0.98;

/// A reference face this square to the normal (cosine) measures its points' depths along it
/// exactly (the rounding of a unit normal's last digits).
const SQUARE_COSINE: f32 = 1.0 - 1e-6;

/// Two edges count as parallel (a line contact with two ends) when the sine of their angle is
/// at most this.
const PARALLEL_SINE: f32 = 0.05;

/// Capacity of the clipped polygon: a feature clipped by as many side planes.
const CLIP_CAPACITY: usize = 2 * MAX_FEATURE_POINTS;

/// Feature-id contexts (module docs), the kind in bits 13–14.
const CLIPPED: u32 = 1 << 13;
const PARALLEL_END: u32 = 2 << 13;
const DEEPEST: u32 = 3 << 13;
const ON_PLANE: u32 = 1 << 12;
const LOWEST: u32 = 2 << 12;

/// Where B's lines start in a clipped point's tag (A's from 0; a feature has at most
/// [`MAX_FEATURE_POINTS`] edges).
const B_LINES: u8 = 0x40;

/// Contact between `a` at `pose_a` and `b` at `pose_b`, any convex shapes (see
/// [`ConvexPart::of_shape`]), with a speculative `margin` (0: touching or overlapping only).
/// Worked in A's frame, so the numbers stay near the pair. `None` when they are farther apart
/// than the margin, or either is not convex.
pub(crate) fn contact_convex_convex(
    a: &Shape,
    pose_a: &Isometry,
    b: &Shape,
    pose_b: &Isometry,
    margin: f32,
) -> Option<ContactManifold> {
    let pa = ConvexPart::of_shape(a, Isometry::IDENTITY)?;
    let pb = ConvexPart::of_shape(b, pose_a.inv_mul(pose_b))?;
    let m = contact_parts(&pa, &pb, margin)?;
    Some(m.transformed(pose_a))
}

/// Contact between two parts in one frame (module docs).
pub(crate) fn contact_parts(
    a: &ConvexPart,
    b: &ConvexPart,
    margin: f32,
) -> Option<ContactManifold> {
    let d = core_distance_within(a, b, margin)?;
    (d.distance <= margin).then(|| manifold(a, b, &d, margin))
}

/// The manifold of two parts whose signed distance along `d.normal` is `d`: clipped features, or
/// the single deepest pair when no face lines up.
pub(crate) fn manifold(
    a: &ConvexPart,
    b: &ConvexPart,
    d: &SignedDistance,
    margin: f32,
) -> ContactManifold {
    let n = d.normal;
    let (fa, fb) = (a.feature(n), b.feature(-n));
    let (on_a, on_b) = exact_witnesses((a, &fa), (b, &fb), d);
    let deepest = ContactPoint::new((on_a + on_b) * 0.5, -d.distance)
        .with_feature(FeatureId::single(DEEPEST));
    let mut points = [ContactPoint::default(); CLIP_CAPACITY];
    let mut len = 0;
    if fa.points().len() >= 2 && fb.points().len() >= 2 {
        let radii = a.rounding + b.rounding;
        // A face of no area (a zero-radius cylinder's cap, a flat box's face) has no side
        // planes to clip with: it cannot be the reference.
        let min_area = 1e-6 * (a.size() + b.size()).powi(2);
        let facing = |f: &Feature, dir: Vec3| {
            f.normal
                .map(|m| m.dot(dir))
                .filter(|&c| c >= REFERENCE_COSINE && polygon_area(f.points()) > min_area)
        };
        // The reference face: whether it is B's, and how square it is to n.
        let reference = match (facing(&fa, n), facing(&fb, -n)) {
            (Some(ca), Some(cb)) if ca >= cb => Some((false, ca)),
            (Some(ca), None) => Some((false, ca)),
            (_, Some(cb)) => Some((true, cb)),
            (None, None) => None,
        };
        // A point can sink no deeper along n than the pair does (EPA's depth is the deepest
        // along its own normal): a tilted reference plane would overstate a far corner. A
        // reference square to n measures each point exactly, and the pair's depth may fall
        // short of them: a mesh triangle's face normal taken at an inactive edge comes with
        // the height of the closest pair's point, not of the part's lowest point over the
        // triangle (a hull box tilted by 2° read points beside a seam up to 0.88 mm shallow).
        let clamp = reference.is_none_or(|(_, cosine)| cosine < SQUARE_COSINE);
        let mut keep = |p: ContactPoint| {
            if p.depth >= -margin && len < CLIP_CAPACITY {
                let depth = if clamp {
                    p.depth.min(deepest.depth)
                } else {
                    p.depth
                };
                points[len] = ContactPoint { depth, ..p };
                len += 1;
            }
        };
        match reference {
            Some((false, _)) => clip((&fa, &fb, false), n, radii, &mut keep),
            Some((true, _)) => clip((&fb, &fa, true), -n, radii, &mut keep),
            None if fa.normal.is_none() && fb.normal.is_none() => {
                parallel_lines(&fa, &fb, n, (a.rounding, b.rounding), &mut keep)
            }
            None => {}
        }
    }
    let found = &points[..len];
    let best = found
        .iter()
        .map(|p| p.depth)
        .fold(f32::NEG_INFINITY, f32::max);
    let mut out = ContactManifold::new(n);
    if found.is_empty() || best < deepest.depth - 1e-5 * (a.size() + b.size()) {
        // The clip missed the deepest point (a rim or corner against an edge of the
        // reference, a subsampled face) or found nothing: keep it first (once).
        out.push(deepest);
    }
    spread_into(out, found)
}

/// The surface points of `d`, exact where a side meets the other at one point (a curved
/// surface, a rim, a vertex: its supporting feature along the normal, `fa` or `fb`, is one
/// point), the other side's then straight across the gap from it. GJK and EPA close in on a
/// curved surface only to their tolerance: the normal comes out within about 1e-6 rad, but the
/// point on the surface slides sideways by up to `√(2 R tol)` (1.1 mm under a ball-shaped
/// ellipsoid of 0.3 m on a box), and the floor's push there, off the line through the centre,
/// turned it: such an ellipsoid resting on a box rolled away, 0.8 m in 20 s. The support point
/// along the normal is exact, and where the point lies does not change the depth.
fn exact_witnesses(
    (a, fa): (&ConvexPart, &Feature),
    (b, fb): (&ConvexPart, &Feature),
    d: &SignedDistance,
) -> (Vec3, Vec3) {
    let n = d.normal;
    let single = |f: &Feature| match f.points() {
        &[p] => Some(p),
        _ => None,
    };
    match (single(fa), single(fb)) {
        (Some(pa), Some(pb)) => (pa + n * a.rounding, pb - n * b.rounding),
        (Some(pa), None) => {
            let on_a = pa + n * a.rounding;
            (on_a, on_a + n * d.distance)
        }
        (None, Some(pb)) => {
            let on_b = pb - n * b.rounding;
            (on_b - n * d.distance, on_b)
        }
        (None, None) => (d.on_a, d.on_b),
    }
}

/// `out` with at most its capacity of `points` added: the deepest, then the widest spread
/// (`manifold_reduction.rs`).
fn spread_into(mut out: ContactManifold, points: &[ContactPoint]) -> ContactManifold {
    let (chosen, count) = spread_points(points, out.normal);
    for &i in &chosen[..count] {
        out.push(points[i]);
    }
    out
}

/// Clips `incident` to the side planes of the face `reference` (B's when `of_b`); `n` points
/// from the reference's shape to the incident's. Each point inside gets its depth below the
/// reference plane along `n` plus the incident's rounding (a face's own core is never rounded),
/// the midpoint between the surfaces, and its feature id (module docs).
fn clip(
    (reference, incident, of_b): (&Feature, &Feature, bool),
    n: Vec3,
    radii: f32,
    keep: &mut impl FnMut(ContactPoint),
) {
    let Some(m) = reference.normal else { return };
    let face = reference.points();
    let centre = face.iter().sum::<Vec3>() / face.len() as f32;
    let mut poly = ClipPolygon::<CLIP_CAPACITY>::from_corners(incident.points());
    for (k, &r) in face.iter().enumerate() {
        let edge = face[(k + 1) % face.len()] - r;
        let mut side = edge.cross(m);
        if side.dot(centre - r) > 0.0 {
            side = -side;
        }
        poly = poly.clipped(side, side.dot(r), FIRST_PLANE + k as u8);
    }
    let ([a, b], [incident_lines, reference_lines]) = if of_b {
        ([incident, reference], [0, B_LINES])
    } else {
        ([reference, incident], [B_LINES, 0])
    };
    let faces = CLIPPED | (a.id & 0x3F) << 6 | (b.id & 0x3F);
    let offset = m.dot(face[0]);
    let along = m.dot(n);
    for (p, tag) in poly.tagged() {
        // The incident core point p lies `sunk` below the reference plane, along n; only the
        // incident side is rounded (faces belong to unrounded cores).
        let sunk = (offset - m.dot(p)) / along;
        let on_reference = p + n * sunk;
        keep(ContactPoint {
            point: (on_reference + p - n * radii) * 0.5,
            depth: radii + sunk,
            feature: if (tag.has_edge() && !incident.numbered)
                || (tag.has_plane() && !reference.numbered)
            {
                // A line of a cap that turns with the query: no name that lasts.
                FeatureId::NONE
            } else {
                let owned = tag.by_owner(incident_lines, reference_lines);
                let id = FeatureId::clipped(faces, owned.bits());
                // A corner of B's own (B meets a mesh's triangles as A): named alike on
                // every triangle.
                if owned.lines_from(B_LINES) {
                    id.of_other_alone()
                } else {
                    id
                }
            },
        });
    }
}

/// Two edges (a capsule's axis, a cylinder's side line) lying parallel: the overlap of their
/// spans, each end with its own gap. (`capsule_capsule.rs` has the same clip for two capsules'
/// axes; here either segment may be rounded or not, and the gap is measured along `n`.)
fn parallel_lines(
    fa: &Feature,
    fb: &Feature,
    n: Vec3,
    (ra, rb): (f32, f32),
    keep: &mut impl FnMut(ContactPoint),
) {
    let ([a0, a1], [b0, b1]) = (first_two(fa), first_two(fb));
    let (da, db) = (a1 - a0, b1 - b0);
    let len2 = da.length_squared();
    if len2 <= 0.0 || da.cross(db).length() > PARALLEL_SINE * da.length() * db.length() {
        return;
    }
    let t = |p: Vec3| (p - a0).dot(da) / len2;
    let (tb0, tb1) = (t(b0), t(b1));
    let (lo, hi) = (tb0.min(tb1).max(0.0), tb0.max(tb1).min(1.0));
    if (tb1 - tb0).abs() <= f32::EPSILON || lo > hi {
        return; // the spans do not overlap: the single deepest point stands
    }
    for (end, ta) in [lo, hi].into_iter().enumerate() {
        let on_a = a0 + da * ta;
        let s = (ta - tb0) / (tb1 - tb0);
        let on_b = b0 + db * s.clamp(0.0, 1.0);
        let gap = (on_b - on_a).dot(n);
        keep(ContactPoint {
            point: (on_a + on_b + n * (ra - rb)) * 0.5,
            depth: ra + rb - gap,
            feature: FeatureId::single(PARALLEL_END + end as u32),
        });
    }
}

/// The area of a planar polygon (half the length of Newell's normal).
fn polygon_area(p: &[Vec3]) -> f32 {
    let mut twice = Vec3::ZERO;
    for (k, &v) in p.iter().enumerate() {
        twice += v.cross(p[(k + 1) % p.len()]);
    }
    0.5 * twice.length()
}

fn first_two(f: &Feature) -> [Vec3; 2] {
    let p = f.points();
    [p[0], p[p.len() - 1]]
}

/// A convex shape `a` at `pose_a` against the half-space `h` at `pose_h`, normal from the shape
/// to the half-space: the shape's supporting feature below the raised plane, each point with its
/// own depth (a standing cylinder rests on its cap's polygon, a lying one on its side line).
pub(crate) fn contact_convex_halfspace(
    a: &Shape,
    pose_a: &Isometry,
    h: &HalfSpace,
    pose_h: &Isometry,
    margin: f32,
) -> Option<ContactManifold> {
    let part = ConvexPart::of_shape(a, *pose_a)?;
    let up = pose_h.transform_vector(h.normal);
    let height = |p: Vec3| up.dot(p - pose_h.translation) - part.rounding;
    let lowest = part.support(-up);
    if height(lowest) > margin {
        return None;
    }
    let normal = -up;
    let mut points = [ContactPoint::default(); MAX_FEATURE_POINTS];
    let mut len = 0;
    let feature = part.feature(normal);
    for (k, &p) in feature.points().iter().enumerate() {
        let gap = height(p);
        if gap <= margin {
            let surface = p - up * part.rounding;
            let name = ON_PLANE | (feature.id & 0x7F) << 5 | k as u32;
            points[len] = ContactPoint {
                point: surface - up * (0.5 * gap),
                depth: -gap,
                feature: if feature.numbered {
                    FeatureId::single(name)
                } else {
                    FeatureId::NONE
                },
            };
            len += 1;
        }
    }
    let mut out = ContactManifold::new(normal);
    if len == 0 {
        let gap = height(lowest);
        out.push(
            ContactPoint::new(lowest - up * (part.rounding + 0.5 * gap), -gap)
                .with_feature(FeatureId::single(LOWEST)),
        );
        return Some(out);
    }
    Some(spread_into(out, &points[..len]))
}

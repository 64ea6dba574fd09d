//! Clipping a convex polygon against a plane (Sutherland & Hodgman 1974, "Reentrant polygon
//! clipping"), in a fixed-size buffer: the face–face contact of two boxes clips a quad against
//! four planes, so it never holds more than eight vertices and needs no heap; the triangle–box
//! contact clips a triangle against six planes, at most nine vertices.
//!
//! **Tags.** Every vertex of a clipped polygon is where two lines of the polygon's plane cross:
//! two edges of the polygon clipped (an original corner), or an edge and a clipping plane, or
//! two clipping planes (a corner of the reference face). Each vertex carries that pair as its
//! tag, edges numbered `0..n` (edge `i` from corner `i` to `i + 1`) and the planes from
//! [`FIRST_PLANE`] in the order given, so the same features meeting give the same tag step
//! after step, wherever they are: the feature ids of the contact points
//! ([`FeatureId`](crate::geometry::FeatureId), Box2D's clip-vertex ids in 3D). An edge of the
//! clipped polygon lies on the one line its two ends share; where it crosses a plane, the new
//! vertex pairs that line with the plane.

use glam::Vec3;

/// Most vertices the box–box [`ClipPolygon`] holds: a quad clipped by four planes, each adding
/// at most one.
pub(crate) const MAX_CLIP_VERTICES: usize = 8;

/// Most vertices the triangle–box [`ClipPolygon`] holds: a triangle clipped by six planes.
pub(crate) const MAX_TRIANGLE_CLIP_VERTICES: usize = 9;

/// The number of the first clipping plane in a tag (edges come before it).
pub(crate) const FIRST_PLANE: u8 = 0x80;

/// The lines naming a segment's two ends (a polygon of two corners), among the edges.
const SEGMENT_END: u8 = 0x7E;

/// A vertex's two lines (module docs), the smaller first.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Tag([u8; 2]);

impl Tag {
    fn new(a: u8, b: u8) -> Self {
        Self([a.min(b), a.max(b)])
    }

    /// The line two neighbouring vertices share (rounding can leave none: then this one's
    /// second, any line of it naming the edge as well as another).
    fn shared(self, other: Self) -> u8 {
        let [a, b] = self.0;
        if a == other.0[0] || a == other.0[1] {
            a
        } else {
            b
        }
    }

    /// The tag with each line renumbered by whose it is: an edge of the clipped polygon `k` as
    /// `incident + k`, the plane `FIRST_PLANE + k` as `reference + k`. When the reference
    /// plane `k` is edge `k` of a face (planes numbered as the face's edges), a vertex where
    /// the same two edges of the two faces cross gets the same tag whichever face clipped the
    /// other.
    pub(crate) fn by_owner(self, incident: u8, reference: u8) -> Self {
        let owned = |l: u8| {
            if l >= FIRST_PLANE {
                reference.wrapping_add(l - FIRST_PLANE)
            } else {
                incident.wrapping_add(l)
            }
        };
        Self::new(owned(self.0[0]), owned(self.0[1]))
    }

    /// Whether either line is an edge of the clipped polygon (not a plane).
    pub(crate) fn has_edge(self) -> bool {
        self.0[0] < FIRST_PLANE
    }

    /// Whether either line is a clipping plane.
    pub(crate) fn has_plane(self) -> bool {
        self.0[1] >= FIRST_PLANE
    }

    /// Whether both lines are numbered from `first` on.
    pub(crate) fn lines_from(self, first: u8) -> bool {
        self.0[0] >= first
    }

    /// The tag as one number.
    pub(crate) fn bits(self) -> u16 {
        u16::from(self.0[0]) << 8 | u16::from(self.0[1])
    }
}

/// A planar convex polygon of at most `N` vertices, in order, each with its [`Tag`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct ClipPolygon<const N: usize> {
    vertices: [Vec3; N],
    tags: [Tag; N],
    len: usize,
}

impl<const N: usize> ClipPolygon<N> {
    fn empty() -> Self {
        Self {
            vertices: [Vec3::ZERO; N],
            tags: [Tag::default(); N],
            len: 0,
        }
    }

    /// The polygon of the first `N` (at most) of `corners`, in order around it; corner `i`
    /// lies on edges `i − 1` and `i`. Two corners are a segment, edge 0 both ways: its ends
    /// are tagged as edge 0 and [`SEGMENT_END`] `+ i` (edges `1, 0` and `0, 1` would name
    /// both ends alike).
    pub(crate) fn from_corners(corners: &[Vec3]) -> Self {
        let mut out = Self::empty();
        let n = corners.len().min(N);
        for (i, &c) in corners[..n].iter().enumerate() {
            let tag = if n == 2 {
                Tag::new(0, SEGMENT_END + i as u8)
            } else {
                Tag::new(((i + n - 1) % n) as u8, i as u8)
            };
            out.push(c, tag);
        }
        out
    }

    /// The quad `corners`, in order around it.
    pub(crate) fn from_quad(corners: [Vec3; 4]) -> Self {
        Self::from_corners(&corners)
    }

    /// The vertices, in order.
    pub(crate) fn vertices(&self) -> &[Vec3] {
        &self.vertices[..self.len]
    }

    /// The vertices with their tags, in order.
    pub(crate) fn tagged(&self) -> impl Iterator<Item = (Vec3, Tag)> + '_ {
        self.vertices()
            .iter()
            .copied()
            .zip(self.tags[..self.len].iter().copied())
    }

    /// The part of the polygon where `normal·x <= offset` (points on the plane are kept, so
    /// touching faces still produce contacts).
    ///
    /// A crossing edge contributes the point where it meets the plane; the interpolation
    /// parameter divides by the difference of two distances of strictly opposite signs, so it
    /// is never a division by zero. Rounding can make a nearly degenerate polygon slightly
    /// non-convex and produce more crossings than a convex one could; vertices past the
    /// capacity are then dropped rather than overflowing.
    ///
    /// `plane` numbers the plane in the new vertices' tags (module docs): from [`FIRST_PLANE`],
    /// one per plane of a clip.
    #[must_use]
    pub(crate) fn clipped(&self, normal: Vec3, offset: f32, plane: u8) -> Self {
        let mut out = Self::empty();
        if self.len == 0 {
            return out;
        }
        let mut prev = self.vertices[self.len - 1];
        let mut prev_tag = self.tags[self.len - 1];
        let mut prev_distance = normal.dot(prev) - offset;
        for (current, tag) in self.tagged() {
            let distance = normal.dot(current) - offset;
            if (prev_distance < 0.0 && distance > 0.0) || (prev_distance > 0.0 && distance < 0.0) {
                let t = prev_distance / (prev_distance - distance);
                out.push(
                    prev + (current - prev) * t,
                    Tag::new(prev_tag.shared(tag), plane),
                );
            }
            if distance <= 0.0 {
                out.push(current, tag);
            }
            prev = current;
            prev_tag = tag;
            prev_distance = distance;
        }
        out
    }

    fn push(&mut self, v: Vec3, tag: Tag) {
        if self.len < N {
            self.vertices[self.len] = v;
            self.tags[self.len] = tag;
            self.len += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(h: f32) -> ClipPolygon<MAX_CLIP_VERTICES> {
        ClipPolygon::from_quad([
            Vec3::new(h, h, 0.0),
            Vec3::new(-h, h, 0.0),
            Vec3::new(-h, -h, 0.0),
            Vec3::new(h, -h, 0.0),
        ])
    }

    fn area<const N: usize>(p: &ClipPolygon<N>) -> f32 {
        let v = p.vertices();
        (0..v.len())
            .map(|i| v[i].cross(v[(i + 1) % v.len()]).z)
            .sum::<f32>()
            * 0.5
    }

    #[test]
    fn clipping_a_square_by_a_diagonal_and_by_its_own_sides() {
        let p = square(1.0);
        // x + y <= 0 keeps half the square: a triangle of area 2.
        let half = p.clipped(Vec3::new(1.0, 1.0, 0.0).normalize(), 0.0, FIRST_PLANE);
        assert_eq!(half.vertices().len(), 3);
        assert!((area(&half) - 2.0).abs() < 1e-6);
        // A plane through a side keeps everything (touching is kept).
        let same = p.clipped(Vec3::X, 1.0, FIRST_PLANE);
        assert_eq!(same.vertices(), p.vertices());
        // A plane beyond the square removes it all.
        assert!(p.clipped(-Vec3::X, -1.5, FIRST_PLANE).vertices().is_empty());
    }

    /// A diamond of half-diagonal `r` moved by `shift`, clipped by the unit square.
    fn diamond_in_square(r: f32, shift: Vec3) -> ClipPolygon<MAX_CLIP_VERTICES> {
        let diamond = ClipPolygon::<MAX_CLIP_VERTICES>::from_quad([
            Vec3::new(r, 0.0, 0.0) + shift,
            Vec3::new(0.0, r, 0.0) + shift,
            Vec3::new(-r, 0.0, 0.0) + shift,
            Vec3::new(0.0, -r, 0.0) + shift,
        ]);
        let mut p = diamond;
        let sides = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y];
        for (k, n) in sides.into_iter().enumerate() {
            p = p.clipped(n, 1.0, FIRST_PLANE + k as u8);
        }
        p
    }

    #[test]
    fn a_square_rotated_45_degrees_clipped_by_a_square_is_an_octagon() {
        let r = 2f32.sqrt();
        let p = diamond_in_square(r, Vec3::ZERO);
        assert_eq!(p.vertices().len(), MAX_CLIP_VERTICES);
        // Area of the unit-half-extent square minus four corner triangles of legs 2 - sqrt(2).
        let leg = 2.0 - r;
        assert!((area(&p) - (4.0 - 2.0 * leg * leg)).abs() < 1e-5);
    }

    #[test]
    fn each_clipped_vertex_is_tagged_with_its_two_lines_and_keeps_the_tag_as_the_polygon_slides() {
        let tags = |p: &ClipPolygon<MAX_CLIP_VERTICES>| -> Vec<u16> {
            p.tagged().map(|(_, t)| t.bits()).collect()
        };
        let r = 2f32.sqrt();
        let octagon = diamond_in_square(r, Vec3::ZERO);
        // Each vertex lies on one diamond edge and one square side.
        for ((v, tag), expected) in octagon.tagged().zip(tags(&octagon)) {
            let [edge, plane] = tag.0;
            assert!(edge < 4 && plane >= FIRST_PLANE, "{v}: {tag:?}");
            assert_eq!(tag.bits(), expected);
        }
        let mut sorted = tags(&octagon);
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), 8, "distinct tags");
        // Slid a little, the same features cross: the same tags, vertex by vertex.
        let slid = diamond_in_square(r, Vec3::new(0.03, -0.02, 0.0));
        assert_eq!(tags(&slid), tags(&octagon));
        // A diamond inside the square keeps its corners: edges i − 1 and i.
        let inside = diamond_in_square(0.9, Vec3::ZERO);
        let corner = |i: u8, j: u8| Tag::new(i, j).bits();
        assert_eq!(
            tags(&inside),
            [corner(3, 0), corner(0, 1), corner(1, 2), corner(2, 3)]
        );
        // Clipped by two sides (x ≤ 1 and y ≤ 1), a large square keeps the square's corner
        // where both planes cross.
        let big = ClipPolygon::<MAX_CLIP_VERTICES>::from_quad([
            Vec3::new(3.0, 3.0, 0.0),
            Vec3::new(-3.0, 3.0, 0.0),
            Vec3::new(-3.0, -3.0, 0.0),
            Vec3::new(3.0, -3.0, 0.0),
        ])
        .clipped(Vec3::X, 1.0, FIRST_PLANE)
        .clipped(Vec3::Y, 1.0, FIRST_PLANE + 1);
        let both = Tag::new(FIRST_PLANE, FIRST_PLANE + 1).bits();
        let at = big.tagged().find(|(_, t)| t.bits() == both);
        assert_eq!(at.map(|(v, _)| v), Some(Vec3::new(1.0, 1.0, 0.0)));
    }
}

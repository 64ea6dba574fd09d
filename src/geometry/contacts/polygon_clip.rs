//! Clipping a convex polygon against a plane (Sutherland & Hodgman 1974, "Reentrant polygon
//! clipping"), in a fixed-size buffer: the face–face contact of two boxes clips a quad against
//! four planes, so it never holds more than eight vertices and needs no heap; the triangle–box
//! contact clips a triangle against six planes, at most nine vertices.

use glam::Vec3;

/// Most vertices the box–box [`ClipPolygon`] holds: a quad clipped by four planes, each adding
/// at most one.
pub(crate) const MAX_CLIP_VERTICES: usize = 8;

/// Most vertices the triangle–box [`ClipPolygon`] holds: a triangle clipped by six planes.
pub(crate) const MAX_TRIANGLE_CLIP_VERTICES: usize = 9;

/// A planar convex polygon of at most `N` vertices, in order.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ClipPolygon<const N: usize> {
    vertices: [Vec3; N],
    len: usize,
}

impl<const N: usize> ClipPolygon<N> {
    /// The polygon of the first `N` (at most) of `corners`, in order around it.
    pub(crate) fn from_corners(corners: &[Vec3]) -> Self {
        let mut out = Self {
            vertices: [Vec3::ZERO; N],
            len: 0,
        };
        for &c in corners {
            out.push(c);
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

    /// The part of the polygon where `normal·x <= offset` (points on the plane are kept, so
    /// touching faces still produce contacts).
    ///
    /// A crossing edge contributes the point where it meets the plane; the interpolation
    /// parameter divides by the difference of two distances of strictly opposite signs, so it
    /// is never a division by zero. Rounding can make a nearly degenerate polygon slightly
    /// non-convex and produce more crossings than a convex one could; vertices past the
    /// capacity are then dropped rather than overflowing.
    #[must_use]
    pub(crate) fn clipped(&self, normal: Vec3, offset: f32) -> Self {
        let mut out = Self {
            vertices: [Vec3::ZERO; N],
            len: 0,
        };
        let Some(&last) = self.vertices().last() else {
            return out;
        };
        let mut prev = last;
        let mut prev_distance = normal.dot(prev) - offset;
        for &current in self.vertices() {
            let distance = normal.dot(current) - offset;
            if (prev_distance < 0.0 && distance > 0.0) || (prev_distance > 0.0 && distance < 0.0) {
                let t = prev_distance / (prev_distance - distance);
                out.push(prev + (current - prev) * t);
            }
            if distance <= 0.0 {
                out.push(current);
            }
            prev = current;
            prev_distance = distance;
        }
        out
    }

    fn push(&mut self, v: Vec3) {
        if self.len < N {
            self.vertices[self.len] = v;
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
        let half = p.clipped(Vec3::new(1.0, 1.0, 0.0).normalize(), 0.0);
        assert_eq!(half.vertices().len(), 3);
        assert!((area(&half) - 2.0).abs() < 1e-6);
        // A plane through a side keeps everything (touching is kept).
        let same = p.clipped(Vec3::X, 1.0);
        assert_eq!(same.vertices(), p.vertices());
        // A plane beyond the square removes it all.
        assert!(p.clipped(-Vec3::X, -1.5).vertices().is_empty());
    }

    #[test]
    fn a_square_rotated_45_degrees_clipped_by_a_square_is_an_octagon() {
        let r = 2f32.sqrt();
        let diamond = ClipPolygon::<MAX_CLIP_VERTICES>::from_quad([
            Vec3::new(r, 0.0, 0.0),
            Vec3::new(0.0, r, 0.0),
            Vec3::new(-r, 0.0, 0.0),
            Vec3::new(0.0, -r, 0.0),
        ]);
        let mut p = diamond;
        for (n, o) in [
            (Vec3::X, 1.0),
            (-Vec3::X, 1.0),
            (Vec3::Y, 1.0),
            (-Vec3::Y, 1.0),
        ] {
            p = p.clipped(n, o);
        }
        assert_eq!(p.vertices().len(), MAX_CLIP_VERTICES);
        // Area of the unit-half-extent square minus four corner triangles of legs 2 - sqrt(2).
        let leg = 2.0 - r;
        assert!((area(&p) - (4.0 - 2.0 * leg * leg)).abs() < 1e-5);
    }
}

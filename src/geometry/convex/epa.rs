//! EPA, the expanding polytope algorithm (van den Bergen 2001, "Proximity queries and
//! penetration depth computation on 3D game objects"): when GJK finds the cores overlapping, the
//! penetration depth is the distance from the origin to the boundary of `A − B`. EPA grows a
//! polytope inside `A − B` from GJK's simplex: it takes the face closest to the origin, adds the
//! support point along that face's normal, removes the faces that point sees and fans the
//! horizon to it, until the support point adds less than a tolerance. The last closest face
//! gives the normal (from A to B), the depth, and by its barycentric weights the witnesses.
//!
//! Fixed-size arrays, no heap: the narrow phase runs EPA per resting pair per step. A simplex of
//! fewer than four points (the cores touch) is first blown up to a tetrahedron with support
//! points along directions off its span, as Bullet and Jolt do.

use super::gjk::{Simplex, SupportPoint, support};
use super::support::ConvexPart;
use glam::{DQuat, DVec3, Vec3};

/// Most polytope vertices.
const MAX_VERTICES: usize = 128;
/// Most polytope faces (a closed triangulated polytope of V vertices has 2V − 4).
const MAX_FACES: usize = 2 * MAX_VERTICES;
/// Iterations EPA may take before answering with its best face.
const MAX_ITERATIONS: usize = MAX_VERTICES - 4;
/// Converged when a support point adds at most this fraction of the pair's size.
const RELATIVE_TOLERANCE: f64 = 1e-6;

/// EPA's answer.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Penetration {
    /// Unit normal from A to B: moving B by `normal * depth` separates the cores.
    pub normal: Vec3,
    /// Penetration depth of the cores, `>= 0`.
    pub depth: f32,
    /// A's core point deepest in B.
    pub on_a: Vec3,
    /// B's core point deepest in A.
    pub on_b: Vec3,
}

#[derive(Clone, Copy, Debug, Default)]
struct Face {
    ids: [u8; 3],
    normal: DVec3,
    distance: f64,
    alive: bool,
}

struct Polytope {
    vertices: [SupportPoint; MAX_VERTICES],
    vertex_count: usize,
    faces: [Face; MAX_FACES],
    face_count: usize,
}

impl Polytope {
    fn add_vertex(&mut self, p: SupportPoint) -> Option<u8> {
        (self.vertex_count < MAX_VERTICES).then(|| {
            self.vertices[self.vertex_count] = p;
            self.vertex_count += 1;
            (self.vertex_count - 1) as u8
        })
    }

    /// Adds the face `ids` (counter-clockwise seen from outside); a sliver without a normal is
    /// kept for the topology but never chosen.
    fn add_face(&mut self, ids: [u8; 3]) -> bool {
        let slot = if self.face_count < MAX_FACES {
            self.face_count += 1;
            self.face_count - 1
        } else if let Some(dead) = self.faces.iter().position(|f| !f.alive) {
            dead
        } else {
            return false;
        };
        let [a, b, c] = ids.map(|i| self.vertices[i as usize].w);
        let (normal, distance) = match (b - a).cross(c - a).try_normalize() {
            Some(n) => (n, n.dot(a)),
            None => (DVec3::Z, f64::INFINITY),
        };
        self.faces[slot] = Face {
            ids,
            normal,
            distance,
            alive: true,
        };
        true
    }

    fn closest_face(&self) -> Option<usize> {
        (0..self.face_count)
            .filter(|&f| self.faces[f].alive)
            .min_by(|&x, &y| self.faces[x].distance.total_cmp(&self.faces[y].distance))
    }

    /// The alive face other than `f` that runs the edge `(j, i)`: `f`'s neighbour across
    /// `(i, j)`.
    fn neighbour(&self, f: usize, (i, j): (u8, u8)) -> Option<usize> {
        (0..self.face_count).find(|&g| {
            let ids = self.faces[g].ids;
            g != f && self.faces[g].alive && (0..3).any(|k| (ids[k], ids[(k + 1) % 3]) == (j, i))
        })
    }

    /// A sliver (no normal) counts as seen: replacing it costs nothing, and its stand-in
    /// normal would decide at random.
    fn sees(&self, f: usize, p: DVec3) -> bool {
        let face = &self.faces[f];
        !face.distance.is_finite()
            || face.normal.dot(p - self.vertices[face.ids[0] as usize].w) > 0.0
    }

    /// Removes the faces the new vertex `new` sees, flooding out from `seed` (which sees it)
    /// across shared edges so that the removed region is connected, as on a convex polytope it
    /// is; fans the horizon (the edges into faces that stay) to `new`.
    fn expand(&mut self, seed: usize, new: u8) -> bool {
        let p = self.vertices[new as usize].w;
        let mut visible = [false; MAX_FACES];
        let mut stack = [0usize; MAX_FACES];
        let mut top = 1;
        stack[0] = seed;
        visible[seed] = true;
        let mut horizon = [(0u8, 0u8); MAX_FACES];
        let mut edges = 0usize;
        while top > 0 {
            top -= 1;
            let f = stack[top];
            let ids = self.faces[f].ids;
            for k in 0..3 {
                let edge = (ids[k], ids[(k + 1) % 3]);
                match self.neighbour(f, edge) {
                    Some(g) if visible[g] => {}
                    Some(g) if self.sees(g, p) && top < MAX_FACES => {
                        visible[g] = true;
                        stack[top] = g;
                        top += 1;
                    }
                    _ if edges < MAX_FACES => {
                        horizon[edges] = edge;
                        edges += 1;
                    }
                    _ => return false,
                }
            }
        }
        for (f, &gone) in visible.iter().enumerate().take(self.face_count) {
            if gone {
                self.faces[f].alive = false;
            }
        }
        horizon[..edges]
            .iter()
            .all(|&(i, j)| self.add_face([i, j, new]))
    }
}

/// Blows a simplex of fewer than four points up to a tetrahedron; `None` when `A − B` is flat.
fn tetrahedron(a: &ConvexPart, b: &ConvexPart, s: &Simplex, eps: f64) -> Option<[SupportPoint; 4]> {
    let mut out = [SupportPoint::default(); 4];
    out[..s.len].copy_from_slice(&s.points[..s.len]);
    let mut len = s.len;
    if len == 1 {
        let found = [
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
        ]
        .into_iter()
        .map(|d| support(a, b, d))
        .find(|p| p.w.distance(out[0].w) > eps)?;
        out[1] = found;
        len = 2;
    }
    if len == 2 {
        let axis = (out[1].w - out[0].w).normalize_or_zero();
        let least = axis.abs().min_element();
        let pick = if axis.x.abs() == least {
            DVec3::X
        } else if axis.y.abs() == least {
            DVec3::Y
        } else {
            DVec3::Z
        };
        let side = axis.cross(pick).normalize_or_zero();
        let off_line = |p: &SupportPoint| (p.w - out[0].w).cross(axis).length() > eps;
        out[2] = (0..6)
            .map(|k| DQuat::from_axis_angle(axis, k as f64 * std::f64::consts::FRAC_PI_3) * side)
            .map(|d| support(a, b, d))
            .find(off_line)?;
        len = 3;
    }
    if len == 3 {
        let n = (out[1].w - out[0].w)
            .cross(out[2].w - out[0].w)
            .normalize_or_zero();
        let off_plane = |p: &SupportPoint| n.dot(p.w - out[0].w).abs() > eps;
        out[3] = [n, -n]
            .into_iter()
            .map(|d| support(a, b, d))
            .find(off_plane)?;
    }
    Some(out)
}

/// The penetration of the cores of `a` and `b`, from GJK's overlapping `simplex`; `None` only
/// when `A − B` has no volume (two flat cores in one plane), where no depth is defined.
pub(crate) fn epa(a: &ConvexPart, b: &ConvexPart, simplex: &Simplex) -> Option<Penetration> {
    let scale = f64::from(a.size() + b.size());
    let tolerance = (RELATIVE_TOLERANCE * scale).max(f64::MIN_POSITIVE);
    let start = tetrahedron(a, b, simplex, tolerance)?;
    let mut poly = Polytope {
        vertices: [SupportPoint::default(); MAX_VERTICES],
        vertex_count: 0,
        faces: [Face::default(); MAX_FACES],
        face_count: 0,
    };
    for p in start {
        poly.add_vertex(p)?;
    }
    // Each face wound so that its normal points away from the fourth vertex.
    for [i, j, k, opposite] in [[0u8, 1, 2, 3], [0, 3, 1, 2], [0, 2, 3, 1], [1, 3, 2, 0]] {
        let w = |i: u8| start[i as usize].w;
        let inward = (w(j) - w(i)).cross(w(k) - w(i)).dot(w(opposite) - w(i)) > 0.0;
        poly.add_face(if inward { [i, k, j] } else { [i, j, k] });
    }
    // A copy, not an index: a failed expansion may leave the slot dead or reused.
    let mut seed = poly.closest_face()?;
    let mut face = poly.faces[seed];
    for _ in 0..MAX_ITERATIONS {
        if !face.distance.is_finite() {
            break;
        }
        let p = support(a, b, face.normal);
        if face.normal.dot(p.w) - face.distance <= tolerance {
            break;
        }
        let Some(new) = poly.add_vertex(p) else { break };
        if !poly.expand(seed, new) {
            break;
        }
        match poly.closest_face() {
            // The closest distance never shrinks on a sound polytope; if rounding broke it,
            // the last sound face stands.
            Some(f) if poly.faces[f].distance >= face.distance - tolerance => {
                seed = f;
                face = poly.faces[f];
            }
            _ => break,
        }
    }
    finite(face.distance)?;
    Some(witnesses(&poly, face))
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// The face's normal and depth, and the witnesses of the origin's projection on it.
fn witnesses(poly: &Polytope, face: Face) -> Penetration {
    let [p0, p1, p2] = face.ids.map(|i| poly.vertices[i as usize]);
    let q = face.normal * face.distance;
    let (v0, v1) = (p1.w - p0.w, p2.w - p0.w);
    let v2 = q - p0.w;
    let (d00, d01, d11) = (v0.dot(v0), v0.dot(v1), v1.dot(v1));
    let (d20, d21) = (v2.dot(v0), v2.dot(v1));
    let denom = d00 * d11 - d01 * d01;
    let (u, v) = if denom > 0.0 {
        let v = ((d11 * d20 - d01 * d21) / denom).clamp(0.0, 1.0);
        let w = ((d00 * d21 - d01 * d20) / denom).clamp(0.0, 1.0 - v);
        (v, w)
    } else {
        (0.0, 0.0)
    };
    let bary = [1.0 - u - v, u, v];
    let on_a = p0.a * bary[0] + p1.a * bary[1] + p2.a * bary[2];
    let on_b = p0.b * bary[0] + p1.b * bary[1] + p2.b * bary[2];
    Penetration {
        normal: face.normal.as_vec3(),
        depth: face.distance.max(0.0) as f32,
        on_a: on_a.as_vec3(),
        on_b: on_b.as_vec3(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::convex::gjk::{Gjk, gjk};
    use crate::geometry::{Isometry, Shape};

    #[test]
    fn overlapping_boxes_give_the_face_depth_within_1e_5() {
        let cube = Shape::cuboid(Vec3::splat(0.5));
        let a = ConvexPart::of_shape(&cube, Isometry::IDENTITY).unwrap();
        let at = Isometry::from_translation(Vec3::new(0.1, -0.2, 0.9));
        let b = ConvexPart::of_shape(&cube, at).unwrap();
        let Gjk::Overlapping(s) = gjk(&a, &b) else {
            panic!("overlap")
        };
        let p = epa(&a, &b, &s).unwrap();
        assert!((p.depth - 0.1).abs() < 1e-5, "{p:?}");
        assert!(p.normal.dot(Vec3::Z) > 1.0 - 1e-5, "{p:?}");
    }
}

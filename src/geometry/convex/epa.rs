//! EPA, the expanding polytope algorithm (van den Bergen 2001, "Proximity queries and
//! penetration depth computation on 3D game objects"): when GJK finds the cores overlapping, the
//! penetration depth is the distance from the origin to the boundary of `A − B`. EPA grows a
//! polytope inside `A − B` from GJK's simplex: it takes the face closest to the origin, adds the
//! support point along that face's normal, removes the faces that point sees and fans the
//! horizon to it, until the support point adds less than a tolerance. The last closest face
//! gives the normal (from A to B), the depth, and by its barycentric weights the witnesses.
//!
//! Each face knows its three neighbours (across the edges `ids[k] → ids[k+1]`), so the faces a
//! new vertex sees are flooded out from the closest face through those links and the horizon
//! is read off where the flood stops: a step costs what it removes and adds, not a scan of
//! every face per edge (as in van den Bergen's silhouette walk and Jolt's `EPAConvexHullBuilder`).
//! The polytope lives in a per-thread scratch whose arrays are cleared, not zero-filled, per
//! call: the narrow phase runs EPA per resting pair per step, and allocates nothing once the
//! scratch has grown. A simplex of fewer than four points (the cores touch) is first blown up to a
//! tetrahedron with support points along directions off its span, as Bullet and Jolt do.

use super::gjk::{Simplex, SupportPoint, support};
use super::support::ConvexPart;
use glam::{DQuat, DVec3, Vec3};
use std::cell::RefCell;

/// Most polytope vertices (their ids are `u8`).
const MAX_VERTICES: usize = 128;
/// Iterations EPA may take before answering with its best face.
const MAX_ITERATIONS: usize = MAX_VERTICES - 4;
/// Converged when a support point adds at most this fraction of the pair's size.
const RELATIVE_TOLERANCE: f64 = 1e-6;
/// "No face" / "no fan face yet" in the adjacency and horizon tables.
const NONE: u16 = u16::MAX;

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

#[derive(Clone, Copy, Debug)]
struct Face {
    /// Corners, counter-clockwise seen from outside.
    ids: [u8; 3],
    /// `adjacent[k]`: the face across the edge `ids[k] → ids[(k + 1) % 3]`.
    adjacent: [u16; 3],
    normal: DVec3,
    /// Distance of the face's plane from the origin; infinite for a sliver without a normal.
    distance: f64,
    alive: bool,
}

/// A horizon edge `(from, to)` of the faces being removed, and the face `outside` that stays
/// across it, whose edge `outside_edge` runs `to → from`.
#[derive(Clone, Copy)]
struct HorizonEdge {
    from: u8,
    to: u8,
    outside: u16,
    outside_edge: u8,
    /// The fan face made on this edge.
    slot: u16,
}

/// The polytope and the scratch of its expansion, reused from call to call.
#[derive(Default)]
struct Polytope {
    vertices: Vec<SupportPoint>,
    faces: Vec<Face>,
    /// Slots of dead faces, reused by new ones.
    free: Vec<u16>,
    /// The flood's stack and the faces it removed.
    stack: Vec<u16>,
    removed: Vec<u16>,
    horizon: Vec<HorizonEdge>,
    /// Per vertex, the fan face whose horizon edge starts (ends) there; `NONE` between calls.
    fan_from: Vec<u16>,
    fan_to: Vec<u16>,
}

thread_local! {
    static POLYTOPE: RefCell<Polytope> = RefCell::new(Polytope::default());
}

impl Polytope {
    fn clear(&mut self) {
        self.vertices.clear();
        self.faces.clear();
        self.free.clear();
        // Sized once: every expansion resets the entries it set.
        self.fan_from.resize(MAX_VERTICES, NONE);
        self.fan_to.resize(MAX_VERTICES, NONE);
    }

    fn add_vertex(&mut self, p: SupportPoint) -> Option<u8> {
        (self.vertices.len() < MAX_VERTICES).then(|| {
            self.vertices.push(p);
            (self.vertices.len() - 1) as u8
        })
    }

    /// Adds the face `ids` (counter-clockwise seen from outside) with its neighbours; a sliver
    /// without a normal is kept for the topology but never chosen. `None` when the face slots
    /// run out (`u16` indices).
    fn add_face(&mut self, ids: [u8; 3], adjacent: [u16; 3]) -> Option<u16> {
        let [a, b, c] = ids.map(|i| self.vertices[i as usize].w);
        let (normal, distance) = match (b - a).cross(c - a).try_normalize() {
            Some(n) => (n, n.dot(a)),
            None => (DVec3::Z, f64::INFINITY),
        };
        let face = Face {
            ids,
            adjacent,
            normal,
            distance,
            alive: true,
        };
        if let Some(slot) = self.free.pop() {
            self.faces[slot as usize] = face;
            return Some(slot);
        }
        let slot = u16::try_from(self.faces.len())
            .ok()
            .filter(|&s| s != NONE)?;
        self.faces.push(face);
        Some(slot)
    }

    /// Links every face of a closed polytope to its neighbours by matching reversed edges
    /// (only the starting tetrahedron: later faces are linked as they are made).
    fn link_all(&mut self) {
        for f in 0..self.faces.len() {
            for k in 0..3 {
                let (i, j) = edge(self.faces[f].ids, k);
                self.faces[f].adjacent[k] = (0..self.faces.len())
                    .find(|&g| g != f && (0..3).any(|m| edge(self.faces[g].ids, m) == (j, i)))
                    .map_or(NONE, |g| g as u16);
            }
        }
    }

    fn closest_face(&self) -> Option<usize> {
        self.faces
            .iter()
            .enumerate()
            .filter(|(_, f)| f.alive)
            .min_by(|(_, x), (_, y)| x.distance.total_cmp(&y.distance))
            .map(|(f, _)| f)
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
    /// is; fans the horizon (the edges into faces that stay) to `new`. `false`, with the
    /// polytope as it was, when rounding made the horizon something other than one loop.
    fn expand(&mut self, seed: usize, new: u8) -> bool {
        if !self.flood(seed, new) || !self.index_fan() {
            // Dead so far: the faces flooded and those still waiting on the stack.
            for &f in self.removed.iter().chain(&self.stack) {
                self.faces[f as usize].alive = true;
            }
            self.reset_fan_index();
            return false;
        }
        self.free.extend_from_slice(&self.removed);
        let fanned = self.fan(new);
        self.reset_fan_index();
        fanned
    }

    /// Marks dead the faces `new` sees, connected to `seed`, into `removed`, and collects the
    /// horizon; `false` on a face with a missing neighbour (a broken topology).
    fn flood(&mut self, seed: usize, new: u8) -> bool {
        let p = self.vertices[new as usize].w;
        self.stack.clear();
        self.removed.clear();
        self.horizon.clear();
        self.faces[seed].alive = false;
        self.stack.push(seed as u16);
        while let Some(f) = self.stack.pop() {
            self.removed.push(f);
            let face = self.faces[f as usize];
            for k in 0..3 {
                let g = face.adjacent[k];
                if g == NONE {
                    return false;
                }
                if !self.faces[g as usize].alive {
                    continue; // already removed
                }
                if self.sees(g as usize, p) {
                    self.faces[g as usize].alive = false;
                    self.stack.push(g);
                    continue;
                }
                let (from, to) = edge(face.ids, k);
                let Some(back) =
                    (0..3).find(|&m| edge(self.faces[g as usize].ids, m) == (to, from))
                else {
                    return false;
                };
                self.horizon.push(HorizonEdge {
                    from,
                    to,
                    outside: g,
                    outside_edge: back as u8,
                    slot: NONE,
                });
            }
        }
        true
    }

    /// Numbers the fan faces by the vertex their horizon edge starts and ends at; `false`
    /// unless every horizon vertex starts exactly one edge and ends exactly one, and the edges
    /// make one loop.
    fn index_fan(&mut self) -> bool {
        for (n, e) in self.horizon.iter().enumerate() {
            let (from, to) = (e.from as usize, e.to as usize);
            if self.fan_from[from] != NONE || self.fan_to[to] != NONE {
                return false;
            }
            self.fan_from[from] = n as u16;
            self.fan_to[to] = n as u16;
        }
        // One loop: the walk from the first edge through the edges that start where each
        // ends comes back after visiting them all (two loops would pinch the polytope).
        if self.horizon.is_empty() {
            return false; // every face seen (slivers): nothing to fan
        }
        let (mut at, mut steps) = (0usize, 0usize);
        loop {
            let next = self.fan_from[self.horizon[at].to as usize];
            steps += 1;
            if next == NONE || steps > self.horizon.len() {
                return false;
            }
            at = next as usize;
            if at == 0 {
                return steps == self.horizon.len();
            }
        }
    }

    fn reset_fan_index(&mut self) {
        for e in &self.horizon {
            self.fan_from[e.from as usize] = NONE;
            self.fan_to[e.to as usize] = NONE;
        }
    }

    /// One face `(from, to, new)` per horizon edge, linked to the face outside and to its two
    /// fan neighbours. Slots are taken first so that the links can name them; `false` when
    /// the slots run out (the polytope is then left half-fanned, and EPA stops on its last
    /// sound face).
    fn fan(&mut self, new: u8) -> bool {
        for n in 0..self.horizon.len() {
            let e = self.horizon[n];
            let Some(slot) = self.add_face([e.from, e.to, new], [e.outside, NONE, NONE]) else {
                return false;
            };
            self.horizon[n].slot = slot;
            self.faces[e.outside as usize].adjacent[e.outside_edge as usize] = slot;
        }
        for e in &self.horizon {
            // Edge to → new borders the fan face starting at `to`; new → from, the one ending
            // at `from`.
            let next = self.horizon[self.fan_from[e.to as usize] as usize].slot;
            let previous = self.horizon[self.fan_to[e.from as usize] as usize].slot;
            self.faces[e.slot as usize].adjacent[1..].copy_from_slice(&[next, previous]);
        }
        true
    }
}

/// The edge `k` of a face: `ids[k] → ids[(k + 1) % 3]`.
fn edge(ids: [u8; 3], k: usize) -> (u8, u8) {
    (ids[k], ids[(k + 1) % 3])
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
    // A fresh polytope only if this thread's is in use or being torn down.
    POLYTOPE
        .try_with(|cell| match cell.try_borrow_mut() {
            Ok(mut poly) => expand_to_depth(&mut poly, a, b, simplex),
            Err(_) => expand_to_depth(&mut Polytope::default(), a, b, simplex),
        })
        .unwrap_or_else(|_| expand_to_depth(&mut Polytope::default(), a, b, simplex))
}

/// EPA proper (module docs) in the polytope `poly`, cleared first.
fn expand_to_depth(
    poly: &mut Polytope,
    a: &ConvexPart,
    b: &ConvexPart,
    simplex: &Simplex,
) -> Option<Penetration> {
    let scale = f64::from(a.size() + b.size());
    let tolerance = (RELATIVE_TOLERANCE * scale).max(f64::MIN_POSITIVE);
    let start = tetrahedron(a, b, simplex, tolerance)?;
    poly.clear();
    for p in start {
        poly.add_vertex(p)?;
    }
    // Each face wound so that its normal points away from the fourth vertex.
    for [i, j, k, opposite] in [[0u8, 1, 2, 3], [0, 3, 1, 2], [0, 2, 3, 1], [1, 3, 2, 0]] {
        let w = |i: u8| start[i as usize].w;
        let inward = (w(j) - w(i)).cross(w(k) - w(i)).dot(w(opposite) - w(i)) > 0.0;
        poly.add_face(if inward { [i, k, j] } else { [i, j, k] }, [NONE; 3])?;
    }
    poly.link_all();
    // A copy, not an index: a fan that ran out of slots leaves the polytope half-built.
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
    Some(witnesses(poly, face))
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
    let a = [p0.a, p1.a, p2.a].map(Vec3::as_dvec3);
    let b = [p0.b, p1.b, p2.b].map(Vec3::as_dvec3);
    let on_a = a[0] * bary[0] + a[1] * bary[1] + a[2] * bary[2];
    let on_b = b[0] * bary[0] + b[1] * bary[1] + b[2] * bary[2];
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
    use crate::test_rng::TestRng;

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

    /// The polytope after EPA on overlapping curved and polytope shapes: every alive face's
    /// three neighbours are alive and name it back across the same edge reversed, and the
    /// alive faces close a sphere (Euler: V − E + F = 2 over the vertices they use).
    #[test]
    fn expanded_polytopes_stay_closed_with_reciprocal_neighbours_on_300_pairs() {
        let mut rng = TestRng::new(15);
        let mut poly = Polytope::default();
        let mut expanded = 0;
        for _ in 0..300 {
            let shape = |r: &mut TestRng| match r.below(4) {
                0 => Shape::cylinder(r.range(0.05, 1.0), r.range(0.05, 1.0)),
                1 => Shape::ellipsoid(r.vec3(0.05, 1.0)),
                2 => Shape::cone(r.range(0.05, 1.0), r.range(0.05, 1.0)),
                _ => Shape::cuboid(r.vec3(0.05, 1.0)),
            };
            let (sa, sb) = (shape(&mut rng), shape(&mut rng));
            let at = Isometry::new(rng.vec3(-0.3, 0.3), rng.rotation());
            let a = ConvexPart::of_shape(&sa, Isometry::IDENTITY).unwrap();
            let b = ConvexPart::of_shape(&sb, at).unwrap();
            let Gjk::Overlapping(s) = gjk(&a, &b) else {
                continue;
            };
            assert!(expand_to_depth(&mut poly, &a, &b, &s).is_some());
            expanded += usize::from(poly.vertices.len() > 4);
            let alive: Vec<usize> = (0..poly.faces.len())
                .filter(|&f| poly.faces[f].alive)
                .collect();
            for &f in &alive {
                for k in 0..3 {
                    let g = poly.faces[f].adjacent[k] as usize;
                    let (i, j) = edge(poly.faces[f].ids, k);
                    assert!(poly.faces[g].alive, "face {f} edge {k} borders a dead face");
                    let back = (0..3).find(|&m| edge(poly.faces[g].ids, m) == (j, i));
                    assert_eq!(back.map(|m| poly.faces[g].adjacent[m] as usize), Some(f));
                }
            }
            let mut used = [false; MAX_VERTICES];
            for &f in &alive {
                for i in poly.faces[f].ids {
                    used[i as usize] = true;
                }
            }
            let v = used.iter().filter(|&&u| u).count() as i64;
            let (e, f) = (3 * alive.len() as i64 / 2, alive.len() as i64);
            assert_eq!(v - e + f, 2, "Euler characteristic");
        }
        assert!(expanded > 100, "only {expanded} pairs grew the polytope");
    }

    /// A tetrahedron around the origin, wound outward and linked.
    fn unit_tetrahedron() -> Polytope {
        let mut poly = Polytope::default();
        poly.clear();
        let corners = [
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(-1.0, -1.0, 1.0),
        ];
        for w in corners {
            poly.add_vertex(SupportPoint {
                w,
                a: w.as_vec3(),
                b: Vec3::ZERO,
            });
        }
        for [i, j, k, opposite] in [[0u8, 1, 2, 3], [0, 3, 1, 2], [0, 2, 3, 1], [1, 3, 2, 0]] {
            let w = |i: u8| corners[i as usize];
            let inward = (w(j) - w(i)).cross(w(k) - w(i)).dot(w(opposite) - w(i)) > 0.0;
            poly.add_face(if inward { [i, k, j] } else { [i, j, k] }, [NONE; 3]);
        }
        poly.link_all();
        poly
    }

    /// A broken link met mid-flood (what rounding could leave): the expansion refuses and
    /// every face it had marked dead is alive again, no slot freed, no fan left indexed.
    #[test]
    fn a_refused_expansion_leaves_every_face_as_it_was() {
        let far = DVec3::splat(10.0); // sees three of the four faces
        let point = SupportPoint {
            w: far,
            a: far.as_vec3(),
            b: Vec3::ZERO,
        };
        let seed = (0..4).find(|&f| unit_tetrahedron().sees(f, far)).unwrap();
        // Either other seen face broken: met first, or met while the third waits on the
        // flood's stack.
        for broken in (0..4).filter(|&f| f != seed && unit_tetrahedron().sees(f, far)) {
            let mut poly = unit_tetrahedron();
            let new = poly.add_vertex(point).unwrap();
            poly.faces[broken].adjacent = [NONE; 3];
            let before: Vec<bool> = poly.faces.iter().map(|f| f.alive).collect();
            assert!(!poly.expand(seed, new));
            let after: Vec<bool> = poly.faces.iter().map(|f| f.alive).collect();
            assert_eq!(after, before, "broken face {broken}");
            assert!(poly.free.is_empty() && poly.faces.len() == 4);
            assert!(poly.fan_from.iter().chain(&poly.fan_to).all(|&n| n == NONE));
        }
        // The same expansion on a sound tetrahedron goes through: the three faces the point
        // sees give way to three fanned to it.
        let mut sound = unit_tetrahedron();
        let new = sound
            .add_vertex(SupportPoint {
                w: far,
                a: far.as_vec3(),
                b: Vec3::ZERO,
            })
            .unwrap();
        assert!(sound.expand(seed, new));
        let fanned = |f: &&Face| f.alive && f.ids.contains(&new);
        assert_eq!(sound.faces.iter().filter(fanned).count(), 3);
        assert_eq!(sound.faces.iter().filter(|f| f.alive).count(), 4);
    }
}

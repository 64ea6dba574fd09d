//! Convex hulls of point clouds: a robust 3D quickhull.
//!
//! Quickhull (Barber, Dobkin & Huhdanpaa, "The quickhull algorithm for convex hulls", ACM TOMS
//! 22(4), 1996) as Dirk Gregorius presents it ("Implementing Quickhull", GDC 2014): from a big
//! tetrahedron, each point goes to the face it is farthest above (its *outside set*); while a
//! face has one, its farthest point (the *eye*) joins the hull: the faces it sees give way to a
//! cone of triangles from their boundary (the *horizon*) to the eye, which takes their points.
//! About O(n log n). Coplanar triangles are merged into polygons at the end.
//!
//! Robustness, hazard by hazard:
//! - **Tolerance** (Gregorius' rule): `eps = 3 · f32::EPSILON · (max|x| + max|y| + max|z|)` over
//!   the points centred on their box and scaled by a power of two to a size near 1 (exact; no
//!   product of tiny or huge coordinates under- or overflows). A point within `eps` of a face's
//!   plane is on it, never an eye: duplicates and points on faces or edges never become vertices.
//! - **Degenerate clouds**: the first tetrahedron is the extremes along the axis of largest
//!   spread, the point farthest from their line, then from their plane; a spread or distance of
//!   at most `eps` is [`HullError::Degenerate`], caught before anything divides by it.
//! - **Exact topology**: whether the eye sees a face is read from its plane distance beyond
//!   `4 eps`, else from Shewchuk's exact `orient3d` on the input points: the hull so far is
//!   exactly convex, the faces seen form a disk, and no cone folds over (with a tolerance alone,
//!   near-coplanar eyes fold thin triangles over their neighbours and wreck later tests).
//!   Normals are f64 cross products of the differences: even thin triangles' are f32-exact.
//! - **Merging**: triangles are grouped, largest first, with neighbours whose corners are within
//!   `eps` of the plane of the group's first; a group whose boundary is not one simple loop, or
//!   has a dent deeper than `eps`, stays as triangles. Corners inside a group vanish; a corner on
//!   only two faces (on an edge) is dropped from both unless one would keep fewer than 3.
//! - **Planes**: a polygon's normal is Newell's (its area vector: no thin piece tilts it), its
//!   offset the largest `normal · v` over its corners; they all lie within `2 eps` below it,
//!   and every input point within `eps` above every plane (`eps` over the scale, in input units).

use super::predicates::orient3d;
use super::shapes::MAX_SHAPE_EXTENT;
use super::{MeshError, TriMesh};
use crate::bounding::Aabb;
use glam::Vec3;
use std::fmt;

/// The neighbours of the first tetrahedron's faces, as laid out in [`Builder::new`].
const TETRA_ADJ: [[usize; 3]; 4] = [[1, 2, 3], [3, 2, 0], [1, 3, 0], [2, 1, 0]];

/// A convex polyhedron built from a point cloud: its vertices, and its faces as planar convex
/// polygons (coplanar triangles merged), each with an outward unit normal.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvexHull {
    vertices: Vec<Vec3>,
    faces: Vec<HullFace>,
    face_indices: Vec<u32>,
    /// Per vertex, the vertices it shares an edge with.
    neighbours: Vec<Vec<u32>>,
}

/// One face of a hull: a convex polygon in the plane `normal · x == offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HullFace {
    /// Outward unit normal.
    pub normal: Vec3,
    /// Plane offset: `normal · x == offset` on the face, `<` inside the hull.
    pub offset: f32,
    first: u32,
    len: u32,
}

/// Why a hull cannot be built.
#[derive(Clone, Debug, PartialEq)]
pub enum HullError {
    /// Fewer than 4 points were given (their count).
    TooFewPoints(usize),
    /// A point with a NaN or infinite coordinate.
    NonFinitePoint {
        /// Position of the point in the input.
        index: usize,
        /// Its coordinates.
        position: Vec3,
    },
    /// A coordinate magnitude above `MAX_SHAPE_EXTENT` (1e6 m), so that products of coordinates
    /// stay finite. Also (carrying the count) more points than `u32` indices can address.
    TooLarge(f32),
    /// All points are (within tolerance) coincident, collinear or coplanar: no volume.
    Degenerate,
}

impl fmt::Display for HullError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let max = MAX_SHAPE_EXTENT;
        match self {
            Self::TooFewPoints(n) => write!(f, "{n} points: a hull needs 4 or more, not coplanar"),
            Self::NonFinitePoint { index, position } => write!(f, "point {index} is {position}"),
            Self::TooLarge(x) => write!(f, "{x} is beyond ±{max}: scale the points down"),
            Self::Degenerate => write!(f, "the points are flat (coplanar): give them thickness"),
        }
    }
}

impl std::error::Error for HullError {}

impl ConvexHull {
    /// The convex hull of `points` (see the module notes for the tolerance and degeneracies).
    /// Its vertices are copies of input points, each an extreme point of the cloud.
    pub fn from_points(points: &[Vec3]) -> Result<Self, HullError> {
        if points.len() < 4 {
            return Err(HullError::TooFewPoints(points.len()));
        }
        for (index, &position) in points.iter().enumerate() {
            let size = position.abs().max_element();
            if !position.is_finite() {
                return Err(HullError::NonFinitePoint { index, position });
            } else if size > MAX_SHAPE_EXTENT {
                return Err(HullError::TooLarge(size));
            }
        }
        if u32::try_from(points.len()).is_err() {
            return Err(HullError::TooLarge(points.len() as f32));
        }
        let center = Aabb::from_points(points.iter().copied()).center();
        let size = points.iter().map(|&q| (q - center).abs().max_element());
        let size = size.fold(0.0, f32::max); // 0 (one point) scales by 2^120: degenerate
        let scale = 2f32.powi(-(size.log2().ceil() as i32).clamp(-120, 120));
        let p: Vec<Vec3> = points.iter().map(|&q| (q - center) * scale).collect();
        let mut builder = Builder::new(&p, points)?;
        builder.run();
        Ok(builder.polygons())
    }

    /// The hull's vertices: only its corners (no interior, mid-edge or mid-face points).
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The faces: convex polygons, no two neighbours coplanar (within tolerance).
    pub fn faces(&self) -> &[HullFace] {
        &self.faces
    }

    /// Indices into [`vertices`](Self::vertices) of a face's corners, counter-clockwise seen from
    /// outside (the right-hand rule gives the outward normal); empty for a face out of range.
    pub fn face_vertices(&self, face: usize) -> &[u32] {
        let (all, range) = (&self.face_indices, |f: &HullFace| {
            f.first as usize..(f.first + f.len) as usize
        });
        self.faces.get(face).map_or(&[], |f| &all[range(f)])
    }

    /// A face's corners as points, in [`face_vertices`](Self::face_vertices) order.
    pub fn face_polygon(&self, face: usize) -> impl Iterator<Item = Vec3> + '_ {
        let ids = self.face_vertices(face).iter();
        ids.map(|&i| self.vertices[i as usize])
    }

    /// The vertex farthest along `dir` (any of them on a tie), GJK's support mapping. Hulls of up
    /// to 16 vertices are scanned; larger ones are climbed from a vertex to its best neighbour
    /// while that is better: on a convex polytope's vertex graph a local maximum of a linear
    /// function is the global one, and strict improvement rules out cycling on ties.
    pub fn support(&self, dir: Vec3) -> Vec3 {
        let v = &self.vertices;
        let mut best = argmax(v.len().min(16), |i| v[i].dot(dir));
        while v.len() > 16 {
            let near = &self.neighbours[best];
            let next = near[argmax(near.len(), |k| v[near[k] as usize].dot(dir))] as usize;
            if v[next].dot(dir) <= v[best].dot(dir) || dir.is_nan() {
                break;
            }
            best = next;
        }
        v[best]
    }

    /// Index of the face whose normal has the largest dot product with `dir`.
    pub fn best_face(&self, dir: Vec3) -> usize {
        argmax(self.faces.len(), |i| self.faces[i].normal.dot(dir))
    }

    /// The surface as triangles (each face fanned from its first corner), outward winding, for
    /// mass properties and drawing.
    pub fn to_trimesh(&self) -> Result<TriMesh, MeshError> {
        let mut triangles = Vec::with_capacity(self.face_indices.len());
        for ids in (0..self.faces.len()).map(|f| self.face_vertices(f)) {
            triangles.extend(ids.windows(2).skip(1).map(|w| [ids[0], w[0], w[1]]));
        }
        TriMesh::new(self.vertices.clone(), triangles)
    }

    /// The box around the vertices, in the hull's frame.
    pub fn local_aabb(&self) -> Aabb {
        Aabb::from_points(self.vertices.iter().copied())
    }

    /// Radius of the smallest origin-centred ball holding the hull (its longest vertex).
    pub fn bounding_radius(&self) -> f32 {
        self.vertices.iter().fold(0.0, |r, v| r.max(v.length()))
    }
}

/// The index in `0..n` with the largest `key` (the first on a tie, 0 if none or all NaN).
fn argmax(n: usize, key: impl Fn(usize) -> f32) -> usize {
    let better = |b: (usize, f32), x: (usize, f32)| if x.1 > b.1 { x } else { b };
    (0..n).map(|i| (i, key(i))).fold((0, f32::MIN), better).0
}

/// Gregorius' tolerance for plane distances among `points` (see the module notes).
fn tolerance(points: &[Vec3]) -> f32 {
    let m = points.iter().fold(Vec3::ZERO, |m, p| m.max(p.abs()));
    3.0 * f32::EPSILON * (m.x + m.y + m.z)
}

/// A triangle of the hull being built. Edge `k` is `v[k] → v[k + 1]`, shared with `adj[k]`.
#[derive(Default)]
struct Tri {
    v: [usize; 3],
    adj: [usize; 3],
    n: Vec3,
    d: f32,
    /// The outside set (point, position): more than `eps` above the plane; and its farthest.
    out: Vec<(usize, Vec3)>,
    far: usize,
    far_d: f32,
    dead: bool,
    /// Stamp of the last eye that sees it.
    mark: u32,
}

/// Buffers reused from eye to eye; an edge is `[from, to, face across]`.
#[derive(Default)]
struct Scratch {
    stack: Vec<usize>,
    seen: Vec<usize>,
    cand: Vec<usize>,
    edges: Vec<[usize; 3]>,
    order: Vec<usize>,
    cone: Vec<usize>,
    pool: Vec<(usize, Vec3)>,
}

/// Quickhull's state: the centred, scaled points `p` for distances, `orig` for exact signs.
#[derive(Default)]
struct Builder<'a> {
    p: &'a [Vec3],
    orig: &'a [Vec3],
    eps: f32,
    tris: Vec<Tri>,
    free: Vec<usize>,
    /// Per point: the stamp of the loop being traced, and the loop's edge leaving the point.
    at: Vec<(u32, usize)>,
    stamp: u32,
}

impl<'a> Builder<'a> {
    /// The first tetrahedron (extremes, farthest from their line, farthest from their plane),
    /// with every other point in an outside set.
    fn new(p: &'a [Vec3], orig: &'a [Vec3]) -> Result<Self, HullError> {
        let (eps, count) = (tolerance(p), p.len());
        let m = p.iter().fold(Vec3::ZERO, |m, q| m.max(q.abs()));
        let axis = Vec3::AXES[m.max_position()]; // the points are centred on their box
        let i = argmax(count, |i| -p[i].dot(axis));
        let j = argmax(count, |j| p[j].dot(axis));
        let dir = (p[j] - p[i]).normalize_or_zero();
        let k = argmax(count, |k| (p[k] - p[i]).cross(dir).length_squared());
        let n = dir.cross(p[k] - p[i]).normalize_or_zero();
        let l = argmax(count, |l| n.dot(p[l] - p[i]).abs());
        let (line, plane) = ((p[k] - p[i]).cross(dir).length(), n.dot(p[l] - p[i]).abs());
        if (p[j] - p[i]).dot(axis).min(line).min(plane) <= eps {
            return Err(HullError::Degenerate);
        }
        let swap = orient3d(orig[i], orig[j], orig[k], orig[l]) > 0.0; // l must be below i, j, k
        let (j, k) = if swap { (k, j) } else { (j, k) };
        let mut b = Self::default();
        (b.p, b.orig, b.eps, b.at) = (p, orig, eps, vec![(0, 0); count]);
        let tetra = [[i, j, k], [i, l, j], [j, l, k], [k, l, i]];
        for (f, v) in tetra.into_iter().enumerate() {
            b.add_tri(v);
            b.tris[f].adj = TETRA_ADJ[f];
        }
        for q in (0..count).filter(|q| ![i, j, k, l].contains(q)) {
            b.assign((q, p[q]), &[0, 1, 2, 3]);
        }
        Ok(b)
    }

    /// A new triangle (its neighbours left to the caller), in a dead one's slot if any.
    fn add_tri(&mut self, v: [usize; 3]) -> usize {
        let [a, b, c] = v.map(|i| self.p[i]);
        let n = (b.as_dvec3() - a.as_dvec3()).cross(c.as_dvec3() - a.as_dvec3());
        let n = n.normalize_or_zero().as_vec3();
        let id = self.free.pop().unwrap_or(self.tris.len());
        if id == self.tris.len() {
            self.tris.push(Tri::default());
        }
        let t = &mut self.tris[id]; // a dead triangle's outside set is empty
        (t.v, t.n, t.d, t.dead) = (v, n, n.dot((a + b + c) / 3.0), false);
        id
    }

    /// Gives point `q` to the face of `faces` it is farthest above, if by more than `eps`.
    fn assign(&mut self, (q, at): (usize, Vec3), faces: &[usize]) {
        let dist = |f: usize| self.tris[f].n.dot(at) - self.tris[f].d;
        let best = faces[argmax(faces.len(), |k| dist(faces[k]))];
        let (top, t) = (dist(best), &mut self.tris[best]);
        if top > self.eps {
            if t.out.is_empty() || top > t.far_d {
                (t.far, t.far_d) = (q, top);
            }
            t.out.push((q, at));
        }
    }

    fn run(&mut self) {
        let mut w = Scratch::default();
        w.stack.extend(0..4);
        while let Some(f) = w.stack.pop() {
            if !self.tris[f].dead && !self.tris[f].out.is_empty() {
                self.add_point(f, &mut w);
            }
        }
    }

    /// Adds face `f`'s farthest point to the hull.
    fn add_point(&mut self, f: usize, w: &mut Scratch) {
        let (p, orig, eps, eye) = (self.p, self.orig, self.eps, self.tris[f].far);
        let sees = |t: &Tri| {
            let d = t.n.dot(p[eye]) - t.d; // clear beyond 4 eps, else decided exactly
            let [a, b, c] = t.v.map(|i| orig[i]);
            d > 4.0 * eps || (d > -4.0 * eps && orient3d(a, b, c, orig[eye]) > 0.0)
        };
        self.stamp += 1;
        (w.seen.clear(), w.edges.clear(), w.cand.push(f));
        while let Some(g) = w.cand.pop() {
            if self.tris[g].mark != self.stamp && sees(&self.tris[g]) {
                self.tris[g].mark = self.stamp;
                w.cand.extend(self.tris[g].adj);
                w.seen.push(g);
            }
        }
        for &g in &w.seen {
            let (t, s) = (&self.tris[g], self.stamp);
            let horizon = (0..3).filter(|&k| self.tris[t.adj[k]].mark != s);
            w.edges
                .extend(horizon.map(|k| [t.v[k], t.v[(k + 1) % 3], t.adj[k]]));
        }
        if !self.trace(&w.edges, &mut w.order) {
            let pool = std::mem::take(&mut self.tris[f].out); // `f` does not see its eye: drop it
            for q in pool.into_iter().filter(|q| q.0 != eye) {
                self.assign(q, &[f]);
            }
            return w.stack.push(f);
        }
        w.cone.clear();
        for &k in &w.order {
            let [a, b, o] = w.edges[k];
            let c = self.add_tri([a, b, eye]);
            let j = (0..3).find(|&j| self.tris[o].v[j] == b).unwrap_or(0);
            (self.tris[c].adj[0], self.tris[o].adj[j]) = (o, c);
            w.cone.push(c);
        }
        let m = w.cone.len();
        for (i, &c) in w.cone.iter().enumerate() {
            let t = &mut self.tris[c];
            (t.adj[1], t.adj[2]) = (w.cone[(i + 1) % m], w.cone[(i + m - 1) % m]);
        }
        for g in w.seen.drain(..) {
            self.tris[g].dead = true;
            w.pool.extend(self.tris[g].out.drain(..));
            self.free.push(g);
        }
        for q in w.pool.drain(..).filter(|q| q.0 != eye) {
            self.assign(q, &w.cone);
        }
        let with_points = w.cone.iter().filter(|&&c| !self.tris[c].out.is_empty());
        w.stack.extend(with_points);
    }

    /// Orders `edges` into one closed loop, writing their indices to `order`; false if they are
    /// not exactly one simple loop.
    fn trace(&mut self, edges: &[[usize; 3]], order: &mut Vec<usize>) -> bool {
        (order.clear(), self.stamp += 1);
        let s = self.stamp;
        for (k, e) in edges.iter().enumerate() {
            if self.at[e[0]].0 == s {
                return false; // a pinch: two edges leave one vertex
            }
            self.at[e[0]] = (s, k);
        }
        let first = edges.first().map_or(0, |e| e[0]);
        let mut v = first;
        for _ in 0..edges.len() {
            if self.at[v].0 != s {
                return false;
            }
            let k = self.at[v].1;
            (self.at[v].0, v) = (0, edges[k][1]); // 0: visited
            order.push(k);
        }
        !edges.is_empty() && v == first
    }

    /// Merges coplanar triangles into polygons, and builds the hull over the input points.
    fn polygons(mut self) -> ConvexHull {
        let (p, eps, tris) = (self.p, self.eps, std::mem::take(&mut self.tris));
        let mut alive: Vec<usize> = (0..tris.len()).filter(|&t| !tris[t].dead).collect();
        alive.sort_by_cached_key(|&t| {
            let [a, b, c] = tris[t].v.map(|i| p[i]);
            std::cmp::Reverse((b - a).cross(c - a).length_squared().to_bits())
        });
        let (mut group, mut stack) = (vec![usize::MAX; tris.len()], vec![]);
        for &s in &alive {
            let (n, d) = (tris[s].n, tris[s].d);
            if group[s] == usize::MAX {
                group[s] = s; // a group is named by its first, largest triangle
                stack.push(s);
            }
            let g = group[s];
            while let Some(t) = stack.pop() {
                for u in tris[t].adj {
                    let on_plane = |i: &usize| (n.dot(p[*i]) - d).abs() <= eps;
                    if group[u] == usize::MAX && tris[u].v.iter().all(on_plane) {
                        group[u] = g;
                        stack.push(u);
                    }
                }
            }
        }
        alive.sort_by_key(|&t| group[t]); // stable: a group's first triangle leads it
        // Each face: its boundary loop `ring[start..end]`, and a normal if it is degenerate.
        let (mut ring, mut loops, mut edges, mut order) =
            (vec![], vec![], vec![[0; 3]; 0], vec![0; 0]);
        for members in alive.chunk_by(|&x, &y| group[x] == group[y]) {
            let (g, many, seed) = (group[members[0]], members.len() > 1, tris[members[0]].n);
            edges.clear();
            for t in members.iter().map(|&t| &tris[t]).filter(|_| many) {
                let out = (0..3).filter(|&k| group[t.adj[k]] != g);
                edges.extend(out.map(|k| [t.v[k], t.v[(k + 1) % 3], 0]));
            }
            let traced = many && self.trace(&edges, &mut order);
            let dent = |i: usize| {
                let ([u, v, _], w) = (edges[order[i]], edges[order[(i + 1) % order.len()]][1]);
                let inward = seed.cross(p[w] - p[u]).normalize_or_zero();
                inward.dot(p[v] - p[u])
            };
            if traced && (0..order.len()).all(|i| dent(i) <= eps) {
                ring.extend(order.iter().map(|&k| edges[k][0]));
                loops.push((ring.len() - order.len(), ring.len(), seed));
            } else {
                for t in members.iter().map(|&t| &tris[t]) {
                    ring.extend(t.v);
                    loops.push((ring.len() - 3, ring.len(), t.n));
                }
            }
        }
        let mut count = vec![0u32; p.len()]; // faces per point; 2: dropped
        ring.iter().for_each(|&v| count[v] += 1);
        for &(start, end, _) in &loops {
            let mut kept = ring[start..end].iter().filter(|&&v| count[v] != 2).count();
            for &v in &ring[start..end] {
                if count[v] == 2 && kept < 3 {
                    (count[v], kept) = (3, kept + 1);
                }
            }
        }
        let (mut vertices, mut faces, mut face_indices) = (vec![], vec![], vec![]);
        let (mut remap, mut poly) = (vec![u32::MAX; p.len()], vec![]);
        for &(start, end, fallback) in &loops {
            poly.clear();
            for &v in ring[start..end].iter().filter(|&&v| count[v] != 2) {
                if remap[v] == u32::MAX {
                    remap[v] = vertices.len() as u32;
                    vertices.push(self.orig[v]);
                }
                (face_indices.push(remap[v]), poly.push(self.orig[v]));
            }
            let c = poly.iter().sum::<Vec3>() / poly.len() as f32;
            let area = |i: usize| (poly[i] - c).cross(poly[(i + 1) % poly.len()] - c);
            let normal = (0..poly.len()).map(area).sum::<Vec3>().try_normalize();
            let normal = normal.unwrap_or(fallback);
            let offset = poly.iter().fold(f32::MIN, |m, c| m.max(normal.dot(*c)));
            let (first, len) = ((face_indices.len() - poly.len()) as u32, poly.len() as u32);
            faces.push(HullFace {
                normal,
                offset,
                first,
                len,
            });
        }
        let mut neighbours = vec![Vec::new(); vertices.len()];
        for f in &faces {
            let ids = &face_indices[f.first as usize..(f.first + f.len) as usize];
            for (i, &a) in ids.iter().enumerate() {
                neighbours[a as usize].push(ids[(i + 1) % ids.len()]);
            }
        }
        ConvexHull {
            vertices,
            faces,
            face_indices,
            neighbours,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3Swizzles;
    use std::collections::HashSet;

    /// splitmix64, for deterministic clouds.
    struct Rng(u64);

    impl Rng {
        /// Uniform in [-1, 1).
        fn next(&mut self) -> f32 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let z = (self.0 ^ (self.0 >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            let z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 23) as f32 - 1.0
        }
        fn vec(&mut self) -> Vec3 {
            Vec3::new(self.next(), self.next(), self.next())
        }
        fn unit(&mut self) -> Vec3 {
            let v = self.vec();
            let inside = (0.01..1.0).contains(&v.length_squared());
            if inside { v.normalize() } else { self.unit() }
        }
        fn cloud(&mut self, n: usize, scale: Vec3, at: Vec3) -> Vec<Vec3> {
            (0..n).map(|_| self.vec() * scale + at).collect()
        }
        fn sphere(&mut self, n: usize) -> Vec<Vec3> {
            (0..n).map(|_| self.unit()).collect()
        }
        /// In the box of half extents `h`, in turn: on a face, on an edge, a corner (repeated),
        /// inside.
        fn boxy(&mut self, n: usize, h: Vec3) -> Vec<Vec3> {
            let snap = [Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::ONE, Vec3::ZERO];
            let mut point = |i: usize| {
                let (p, m) = (self.vec(), snap[i % 4]);
                let m = [m, m.zxy(), m.yzx()][i / 4 % 3];
                (p + (p.signum() - p) * m) * h
            };
            (0..n).map(&mut point).collect()
        }
    }

    /// Everything the hull promises, within the input's tolerance (every `step`-th point is
    /// checked against every plane).
    fn check(points: &[Vec3], h: &ConvexHull, step: usize) {
        let tol = tolerance(points);
        let bits = |p: &Vec3| p.to_array().map(f32::to_bits);
        let inputs: HashSet<_> = points.iter().map(bits).collect();
        assert!(
            h.vertices().iter().all(|v| inputs.contains(&bits(v))),
            "a vertex not input"
        );
        let (mut edges, mut faces_at) = (HashSet::new(), vec![0; h.vertices().len()]);
        for (f, face) in h.faces().iter().enumerate() {
            let (ids, poly) = (h.face_vertices(f), h.face_polygon(f).collect::<Vec<_>>());
            let (m, n, mut turning) = (poly.len(), face.normal, 0.0);
            assert!((n.length() - 1.0).abs() < 1e-5);
            for i in 0..m {
                let (u, v, w) = (poly[(i + m - 1) % m], poly[i], poly[(i + 1) % m]);
                assert!(edges.insert((ids[i], ids[(i + 1) % m])), "an edge twice");
                faces_at[ids[i] as usize] += 1;
                let dent = n.cross(w - u).normalize().dot(v - u);
                assert!(dent <= tol, "face {f} has a dent of {dent} at {v}");
                assert!(face.offset - n.dot(v) <= 2.0 * tol, "face {f} not planar");
                turning += n.dot((v - u).cross(w - v)).atan2((v - u).dot(w - v));
            }
            let turns = turning / std::f32::consts::TAU;
            assert!((turns - 1.0).abs() < 1e-3, "face {f} turns {turns} times");
            for &q in points.iter().step_by(step) {
                let above = n.dot(q) - face.offset;
                assert!(above <= tol, "{q} above face {f} by {above} > {tol}");
            }
        }
        assert!(
            edges.iter().all(|&(a, b)| edges.contains(&(b, a))),
            "not closed"
        );
        assert!(faces_at.iter().all(|&n| n >= 3), "a vertex not a corner");
        let (v, e, f) = (h.vertices().len(), edges.len() / 2, h.faces().len());
        assert_eq!(v + f, e + 2, "Euler: V - E + F = 2");
    }

    #[test]
    fn random_clouds_are_convex_within_tolerance() {
        let (mut rng, flat, needle) = (
            Rng(1),
            Vec3::new(1.0, 1.0, 5e-4),
            Vec3::new(1.0, 1e-3, 1e-3),
        );
        for _ in 0..10 {
            let clouds = [
                rng.cloud(1000, Vec3::ONE, Vec3::ZERO),
                rng.sphere(1000),
                rng.boxy(1000, Vec3::new(1.0, 0.5, 0.25)), // coplanar, on edges, repeated
                rng.cloud(1000, flat, Vec3::ZERO),
                rng.cloud(1000, needle, Vec3::ZERO),
                rng.cloud(1000, Vec3::splat(1e3), Vec3::new(3e3, 0.0, 0.0)),
                rng.cloud(1000, Vec3::splat(1e-3), Vec3::ZERO),
            ];
            for points in clouds {
                check(&points, &ConvexHull::from_points(&points).unwrap(), 1);
            }
        }
    }

    #[test]
    fn dense_sphere_of_200k_points_is_convex_within_tolerance() {
        // Neighbours ~0.008 apart bulge ~1e-5: the hardest case for plane tests in f32.
        let points = Rng(8).sphere(200_000);
        check(&points, &ConvexHull::from_points(&points).unwrap(), 200);
    }

    #[test]
    fn cube_cloud_has_exactly_8_vertices_and_6_quads() {
        let mut points = Rng(2).boxy(1000, Vec3::ONE);
        let grid = (0..25).map(|i| Vec3::new(1.0, (i % 5) as f32 - 2.0, (i / 5) as f32 - 2.0));
        let grid = grid.map(|g| g * Vec3::new(1.0, 0.5, 0.5));
        points.extend(grid.flat_map(|g| [g, -g, g.zxy(), -g.zxy(), g.yzx(), -g.yzx()]));
        let h = ConvexHull::from_points(&points).unwrap();
        check(&points, &h, 1);
        assert_eq!((h.vertices().len(), h.faces().len()), (8, 6));
        assert!((0..6).all(|f| h.face_vertices(f).len() == 4 && h.faces()[f].offset == 1.0));
        assert_eq!(
            h.faces()[h.best_face(Vec3::new(0.1, -0.9, 0.2))].normal,
            Vec3::NEG_Y
        );
        assert_eq!(h.local_aabb(), Aabb::new(Vec3::NEG_ONE, Vec3::ONE));
        assert_eq!(h.bounding_radius(), 3f32.sqrt());
    }

    #[test]
    fn too_few_flat_collinear_coincident_nan_and_huge_points_are_errors() {
        let (mut rng, u, v) = (Rng(3), Vec3::new(1.0, 2.0, 3.0), Vec3::new(3.0, -1.0, 0.5));
        let err = |p: &[Vec3]| ConvexHull::from_points(p).err();
        let flat: Vec<Vec3> = (0..100).map(|_| rng.next() * u + rng.next() * v).collect();
        let line: Vec<Vec3> = (0..100).map(|_| rng.next() * v + u).collect();
        assert_eq!(err(&flat[..3]), Some(HullError::TooFewPoints(3)));
        for degenerate in [&flat[..], &line, &[v; 10]] {
            assert_eq!(err(degenerate), Some(HullError::Degenerate));
        }
        let mut bad = rng.boxy(10, Vec3::ONE);
        bad[5].y = f32::NAN;
        assert!(matches!(
            err(&bad),
            Some(HullError::NonFinitePoint { index: 5, .. })
        ));
        bad[5].y = -2e6;
        assert_eq!(err(&bad), Some(HullError::TooLarge(2e6)));
    }

    #[test]
    fn million_points_in_a_ball_build_in_under_2s_in_release() {
        let mut rng = Rng(4);
        let points: Vec<Vec3> = (0..1_000_000)
            .map(|_| rng.unit() * rng.next().abs().cbrt())
            .collect();
        let start = std::time::Instant::now();
        let h = ConvexHull::from_points(&points).unwrap();
        let time = start.elapsed().as_secs_f32();
        println!(
            "1e6 points in a ball: {time} s, {} vertices",
            h.vertices().len()
        );
        assert!(
            h.vertices().len() > 100 && (cfg!(debug_assertions) || time < 2.0),
            "{time} s"
        );
        check(&points, &h, 100);
    }

    #[test]
    fn support_is_the_brute_force_max_for_1000_directions() {
        let mut rng = Rng(6);
        for points in [rng.sphere(300), rng.boxy(1000, Vec3::ONE)] {
            let h = ConvexHull::from_points(&points).unwrap();
            assert!(h.vertices().len() > 16 || h.vertices().len() == 8);
            for dir in (0..1000).map(|_| rng.vec()) {
                let best = h.vertices().iter().fold(f32::MIN, |m, v| m.max(v.dot(dir)));
                assert_eq!(h.support(dir).dot(dir), best, "along {dir}");
            }
        }
    }

    #[test]
    fn volume_matches_parry3d_within_1e_4_relative() {
        let mut rng = Rng(7);
        let volume = |m: &TriMesh| {
            let v = |i: u32| m.vertices()[i as usize];
            let six = m
                .triangles()
                .iter()
                .map(|&[a, b, c]| v(a).dot(v(b).cross(v(c))));
            six.sum::<f32>() / 6.0
        };
        for i in 0..20 {
            let points = [rng.cloud(500, Vec3::ONE, Vec3::ZERO), rng.sphere(500)][i % 2].clone();
            let (vertices, triangles) = parry3d::transformation::convex_hull(&points);
            let theirs = volume(&TriMesh::new(vertices, triangles).unwrap());
            let ours = volume(
                &ConvexHull::from_points(&points)
                    .unwrap()
                    .to_trimesh()
                    .unwrap(),
            );
            assert!(
                (ours - theirs).abs() <= 1e-4 * theirs,
                "{ours} vs parry3d {theirs}"
            );
        }
    }
}

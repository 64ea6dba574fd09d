//! Convex hulls of point clouds: a robust 3D quickhull.
//!
//! Quickhull (Barber, Dobkin & Huhdanpaa, "The quickhull algorithm for convex hulls", ACM TOMS
//! 22(4), 1996) as Dirk Gregorius presents it ("Implementing Quickhull", GDC 2014): from a big
//! tetrahedron, each point goes to the face it is farthest above; while a face has points, the
//! farthest (the *eye*) joins the hull: the faces it sees give way to a cone of triangles from
//! their boundary (the *horizon*) to it, which takes their points. About O(n log n). Robustness:
//! - **Tolerance** (Gregorius' rule): `eps = 3 · f32::EPSILON · (max|x| + max|y| + max|z|)` over
//!   the points centred on their box and scaled by a power of two to a size near 1 (exact). A
//!   point within `eps` of a plane is on it, never an eye: duplicates and points on faces or
//!   edges do not become vertices.
//! - **Degenerate clouds**: the first tetrahedron is the extremes along the axis of largest
//!   spread, the point farthest from their line, then from their plane; a spread or distance of
//!   at most `eps` (or a thin tetrahedron whose faces merge) is [`HullError::Degenerate`].
//! - **Exact topology**: an eye sees a face if its plane distance is beyond `4 eps`, else by
//!   Shewchuk's exact `orient3d` on the inputs: the hull stays exactly convex, the faces seen
//!   form a disk, no cone folds over (as thin triangles do under near-coplanar eyes with a
//!   tolerance alone). Normals are f64 cross products of differences: f32-exact even for slivers.
//! - **Merging**: triangles join, largest first, groups whose corners are all within `eps` of
//!   the first one's plane; a group whose boundary is not one simple loop or is dented deeper
//!   than `eps` stays as triangles. Corners inside a group or on only two faces (on an edge)
//!   vanish. Planes: Newell's normal (the area vector), and the largest `normal · v` as offset:
//!   corners lie within `2 eps` below, input points within `2 eps` above (`eps` over the scale).

use super::hull_lanes::{SCANNED_VERTICES, SupportLanes};
use super::predicates::orient3d;
use super::shapes::MAX_SHAPE_EXTENT;
use super::{MeshError, TriMesh, length_or_zero};
use crate::bounding::Aabb;
use glam::{DVec3, Vec3, Vec4};
use std::fmt;

/// A convex polyhedron built from a point cloud: its vertices, and its faces as planar convex
/// polygons (coplanar triangles merged), each with an outward unit normal.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvexHull {
    vertices: Vec<Vec3>,
    faces: Vec<HullFace>,
    /// Face `f`'s corners are `face_indices[face_start[f]..face_start[f + 1]]`.
    face_indices: Vec<u32>,
    face_start: Vec<u32>,
    /// Vertex `v`'s neighbours (the vertices it shares an edge with) are
    /// `neighbours[neighbour_start[v]..neighbour_start[v + 1]]`: one array, not one per vertex.
    neighbours: Vec<u32>,
    neighbour_start: Vec<u32>,
    /// The first vertices laid out for the support scan.
    lanes: SupportLanes,
    /// The longest vertex, taken once: the manifold cache asks for it on every lookup of a
    /// hull pair.
    bounding_radius: f32,
    /// The nearest face plane (0 with the origin outside), taken once as the longest vertex.
    inner_radius: f32,
}

/// One face of a hull: a convex polygon in the plane `normal · x == offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HullFace {
    /// Outward unit normal.
    pub normal: Vec3,
    /// Plane offset: `normal · x == offset` on the face, `<` inside the hull.
    pub offset: f32,
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
    /// A coordinate magnitude above `MAX_SHAPE_EXTENT` (1e6 m): products would lose finiteness.
    TooLarge(f32),
    /// All points are (within tolerance) coincident, collinear or coplanar: no volume.
    Degenerate,
}

impl fmt::Display for HullError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let max = MAX_SHAPE_EXTENT;
        match self {
            Self::TooFewPoints(n) => write!(f, "{n} points: a hull needs 4 or more, not coplanar"),
            Self::NonFinitePoint { index, .. } => write!(f, "point {index} is not finite: drop it"),
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
        if let Some(index) = points.iter().position(|p| !p.is_finite()) {
            let position = points[index];
            return Err(HullError::NonFinitePoint { index, position });
        }
        let big = |p: &&Vec3| p.abs().max_element() > MAX_SHAPE_EXTENT;
        if let Some(p) = points.iter().find(big) {
            return Err(HullError::TooLarge(p.abs().max_element()));
        }
        let center = Aabb::from_points(points.iter().copied()).center();
        let size = points.iter().map(|&q| (q - center).abs().max_element());
        let size = size.fold(0.0, f32::max); // 0 (one point) scales by 2^120: degenerate
        let scale = 2f32.powi(-(size.log2().ceil() as i32).clamp(-120, 120));
        let p: Vec<Vec3> = points.iter().map(|&q| (q - center) * scale).collect();
        Builder::new(&p, points)?.hull()
    }

    /// The hull's vertices: only its corners (no interior, mid-edge or mid-face points).
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The faces: convex polygons (coplanar triangles merged wherever the result stays convex).
    pub fn faces(&self) -> &[HullFace] {
        &self.faces
    }

    /// Indices into [`vertices`](Self::vertices) of a face's corners, counter-clockwise seen from
    /// outside (the right-hand rule gives the outward normal); empty for a face out of range.
    pub fn face_vertices(&self, face: usize) -> &[u32] {
        let s = self.face_start.get(face..).unwrap_or(&[]);
        let all = &self.face_indices;
        s.get(1).map_or(&[], |&e| &all[s[0] as usize..e as usize])
    }

    /// A face's corners as points, in [`face_vertices`](Self::face_vertices) order.
    pub fn face_polygon(&self, face: usize) -> impl Iterator<Item = Vec3> + '_ {
        let ids = self.face_vertices(face).iter();
        ids.map(|&i| self.vertices[i as usize])
    }

    /// The vertex farthest along `dir` (any on a tie), for GJK: the best of the first 16 vertices
    /// (all of a small hull; scanned four at a time, `hull_lanes.rs`), then a better neighbour
    /// while there is one. On a convex polytope's
    /// vertex graph a local maximum of a linear function is global; strict gains cannot cycle.
    pub fn support(&self, dir: Vec3) -> Vec3 {
        self.vertices[self.support_index(dir)]
    }

    /// The index of [`support`](Self::support)'s vertex. GJK reads the vertex itself: a `Vec3`
    /// returned from a call came back through memory in an 8- and a 4-byte store, and the
    /// caller's first load straddled them (a failed store-to-load forwarding, found with `perf
    /// annotate`), where an index comes back in a register.
    pub fn support_index(&self, dir: Vec3) -> usize {
        let v = &self.vertices;
        let mut best = self.lanes.farthest(dir);
        let higher = |b: usize| self.neighbours_of(b).iter().map(|&n| n as usize);
        let higher = |b: usize| higher(b).find(|&n| v[n].dot(dir) > v[b].dot(dir));
        while v.len() > SCANNED_VERTICES
            && let Some(n) = higher(best)
        {
            best = n;
        }
        best
    }

    /// The vertices sharing an edge with vertex `v`.
    fn neighbours_of(&self, v: usize) -> &[u32] {
        let (start, end) = (self.neighbour_start[v], self.neighbour_start[v + 1]);
        &self.neighbours[start as usize..end as usize]
    }

    /// Index of the face whose normal has the largest dot product with `dir`.
    pub fn best_face(&self, dir: Vec3) -> usize {
        argmax(self.faces.len(), |i| self.faces[i].normal.dot(dir))
    }

    /// The surface as triangles (faces fanned), outward winding: for mass properties, drawing.
    pub fn to_trimesh(&self) -> Result<TriMesh, MeshError> {
        let mut triangles = Vec::with_capacity(self.face_indices.len());
        for ids in (0..self.faces.len()).map(|f| self.face_vertices(f)) {
            triangles.extend((2..ids.len()).map(|i| [ids[0], ids[i - 1], ids[i]]));
        }
        TriMesh::new(self.vertices.clone(), triangles)
    }

    /// The box around the vertices, in the hull's frame.
    pub fn local_aabb(&self) -> Aabb {
        Aabb::from_points(self.vertices.iter().copied())
    }

    /// Radius of the smallest origin-centred ball holding the hull (its longest vertex).
    pub fn bounding_radius(&self) -> f32 {
        self.bounding_radius
    }

    /// Radius of the largest origin-centred ball inside the hull (asked for every substep).
    pub fn inner_radius(&self) -> f32 {
        self.inner_radius
    }
}

/// The index in `0..n` with the largest `key` (the first on a tie, 0 if none or all NaN).
fn argmax(n: usize, key: impl Fn(usize) -> f32) -> usize {
    max_at(n, key).0
}

/// [`argmax`] with the largest key.
fn max_at(n: usize, key: impl Fn(usize) -> f32) -> (usize, f32) {
    let better = |b: (usize, f32), x: (usize, f32)| if x.1 > b.1 { x } else { b };
    (0..n).map(|i| (i, key(i))).fold((0, f32::MIN), better)
}

/// Gregorius' tolerance for plane distances among `points` (see the module notes).
fn tolerance(points: &[Vec3]) -> f32 {
    let m = points.iter().fold(Vec3::ZERO, |m, p| m.max(p.abs()));
    3.0 * f32::EPSILON * (m.x + m.y + m.z)
}

/// The end of an outside set's list.
const NO_POINT: usize = usize::MAX;

/// A triangle of the hull being built: edge `k` is `v[k] → v[k + 1]`, shared with `adj[k]`;
/// `out` the first point of its outside set ([`NO_POINT`] when empty; the others follow
/// through [`Builder::next`]), `mark` the stamp of the last eye seeing it.
#[derive(Default)]
struct Tri {
    v: [usize; 3],
    adj: [usize; 3],
    n: Vec3,
    d: f32,
    out: usize,
    dead: bool,
    mark: u32,
}

impl Tri {
    /// The plane as `(n, −d)`: `plane · (x, 1)` is the height of `x` above it.
    fn plane(&self) -> Vec4 {
        self.n.extend(-self.d)
    }
}

/// Buffers reused from eye to eye; an edge is `[from, to, face across]`.
#[derive(Default)]
struct Scratch {
    stack: Vec<usize>,
    seen: Vec<usize>,
    cand: Vec<usize>,
    edges: Vec<[usize; 3]>,
    cone: Vec<usize>,
    /// The cone's planes, side by side: each orphaned point is measured against all of them.
    planes: Vec<Vec4>,
    /// The points of the faces an eye removed, to be given to its cone.
    pool: Vec<usize>,
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
    /// The loop [`trace`](Self::trace) puts in order, kept for its capacity.
    ring: Vec<[usize; 3]>,
    /// Per point, the next point of the outside set it is in: the sets are lists threaded
    /// through one array, so that a face made or removed allocates nothing (Jolt's
    /// `ConvexHullBuilder` keeps a vector per face, as this one did: most of a small hull's
    /// allocations).
    next: Vec<usize>,
}

impl<'a> Builder<'a> {
    /// The first tetrahedron (see the module notes), with every other point in an outside set.
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
        // Room for the hull's triangles from the start (at most 2n - 4 alive, a few dead
        // between eyes): a small hull's build was a fifth allocations growing one by one.
        let room = 2 * count.min(4096) + 8;
        let mut b = Self {
            tris: Vec::with_capacity(room),
            free: Vec::with_capacity(room / 4),
            ring: Vec::with_capacity(32),
            ..Self::default()
        };
        (b.p, b.orig, b.eps, b.at) = (p, orig, eps, vec![(0, 0); count]);
        b.next = vec![NO_POINT; count];
        let tetra = [[i, j, k], [i, l, j], [j, l, k], [k, l, i]];
        let adj = [[1, 2, 3], [3, 2, 0], [1, 3, 0], [2, 1, 0]]; // the faces' neighbours
        for (v, adj) in tetra.into_iter().zip(adj) {
            b.add_tri(v, adj);
        }
        let planes = [0, 1, 2, 3].map(|t| b.tris[t].plane());
        for q in (0..count).filter(|q| ![i, j, k, l].contains(q)) {
            b.assign(q, &[0, 1, 2, 3], &planes);
        }
        Ok(b)
    }

    /// A new triangle, in a dead one's slot if any.
    fn add_tri(&mut self, v: [usize; 3], adj: [usize; 3]) -> usize {
        let [a, b, c] = v.map(|i| self.p[i]);
        let n = (b.as_dvec3() - a.as_dvec3()).cross(c.as_dvec3() - a.as_dvec3());
        let n = n.normalize_or_zero().as_vec3();
        let id = self.free.pop().unwrap_or(self.tris.len());
        self.tris
            .resize_with(self.tris.len().max(id + 1), Tri::default);
        let t = &mut self.tris[id];
        (t.v, t.adj, t.n, t.d, t.dead) = (v, adj, n, n.dot((a + b + c) / 3.0), false);
        t.out = NO_POINT;
        id
    }

    /// Gives point `q` to the face of `faces` (whose planes are `planes`) it is farthest above,
    /// if by more than `eps`.
    fn assign(&mut self, q: usize, faces: &[usize], planes: &[Vec4]) {
        let at1 = self.p[q].extend(1.0);
        let (best, height) = max_at(planes.len(), |k| planes[k].dot(at1));
        if height > self.eps {
            let face = &mut self.tris[faces[best]];
            self.next[q] = face.out;
            face.out = q;
        }
    }

    /// The points of face `f`'s outside set.
    fn outside(&self, f: usize) -> impl Iterator<Item = usize> + '_ {
        let first = self.tris[f].out;
        std::iter::successors((first != NO_POINT).then_some(first), |&q| {
            let next = self.next[q];
            (next != NO_POINT).then_some(next)
        })
    }

    /// Takes point `q` out of face `f`'s outside set.
    fn unlink(&mut self, f: usize, q: usize) {
        if self.tris[f].out == q {
            self.tris[f].out = self.next[q];
        } else {
            let before = self.outside(f).find(|&r| self.next[r] == q);
            if let Some(before) = before {
                self.next[before] = self.next[q];
            }
        }
    }

    /// Adds face `f`'s farthest point to the hull.
    fn add_point(&mut self, f: usize, w: &mut Scratch) {
        let (t, p, orig, eps) = (&self.tris[f], self.p, self.orig, self.eps);
        // The farthest point; on a tie the lowest index (the list's order is the assignments').
        let height = |q: &usize| (t.n.dot(p[*q]), std::cmp::Reverse(*q));
        let eye = self.outside(f).max_by(|x, y| {
            height(x)
                .partial_cmp(&height(y))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        let Some(eye) = eye else { return };
        let sees = |t: &Tri| {
            let d = t.n.dot(p[eye]) - t.d; // clear beyond 4 eps, else decided exactly
            let [a, b, c] = t.v.map(|i| orig[i]);
            d > 4.0 * eps || (d > -4.0 * eps && orient3d(a, b, c, orig[eye]) > 0.0)
        };
        self.stamp += 1;
        w.seen.clear();
        w.edges.clear();
        w.cand.push(f);
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
            let edge = |k: usize| [t.v[k], t.v[(k + 1) % 3], t.adj[k]];
            w.edges.extend(horizon.map(edge));
        }
        if !self.trace(&mut w.edges) {
            self.unlink(f, eye); // `f` does not see its eye after all
            return w.stack.push(f);
        }
        for &[a, b, o] in &w.edges {
            let c = self.add_tri([a, b, eye], [o, 0, 0]);
            let j = (0..3).find(|&j| self.tris[o].v[j] == b).unwrap_or(0);
            self.tris[o].adj[j] = c;
            w.cone.push(c);
        }
        let m = w.cone.len();
        for (i, &c) in w.cone.iter().enumerate() {
            let t = &mut self.tris[c];
            (t.adj[1], t.adj[2]) = (w.cone[(i + 1) % m], w.cone[(i + m - 1) % m]);
        }
        for g in w.seen.drain(..) {
            w.pool.extend(self.outside(g));
            (self.tris[g].dead, self.tris[g].out) = (true, NO_POINT);
            self.free.push(g);
        }
        w.planes.clear();
        w.planes
            .extend(w.cone.iter().map(|&c| self.tris[c].plane()));
        for q in w.pool.drain(..).filter(|&q| q != eye) {
            self.assign(q, &w.cone, &w.planes);
        }
        let with_points = w.cone.drain(..).filter(|&c| self.tris[c].out != NO_POINT);
        w.stack.extend(with_points);
    }

    /// Puts `edges` in order along their loop; false unless they are exactly one simple loop.
    fn trace(&mut self, edges: &mut Vec<[usize; 3]>) -> bool {
        self.stamp += 1;
        for (k, e) in edges.iter().enumerate() {
            self.at[e[0]] = (self.stamp, k);
        }
        let first = edges.first().map_or(0, |e| e[0]);
        self.ring.clear();
        let mut v = first;
        while self.at[v].0 == self.stamp {
            let k = self.at[v].1;
            (self.at[v].0, v) = (0, edges[k][1]); // 0: visited
            self.ring.push(edges[k]);
        }
        let closed = !edges.is_empty() && self.ring.len() == edges.len() && v == first;
        std::mem::swap(edges, &mut self.ring);
        closed
    }

    /// Runs quickhull, then merges coplanar triangles into the hull's polygons.
    fn hull(mut self) -> Result<ConvexHull, HullError> {
        let mut w = Scratch {
            stack: Vec::with_capacity(64),
            seen: Vec::with_capacity(32),
            cand: Vec::with_capacity(64),
            edges: Vec::with_capacity(32),
            cone: Vec::with_capacity(32),
            planes: Vec::with_capacity(32),
            pool: Vec::with_capacity(self.p.len().min(4096)),
        };
        w.stack.extend(0..4);
        while let Some(f) = w.stack.pop() {
            if !self.tris[f].dead && self.tris[f].out != NO_POINT {
                self.add_point(f, &mut w);
            }
        }
        let (p, eps, tris) = (self.p, self.eps, std::mem::take(&mut self.tris));
        let mut alive: Vec<usize> = (0..tris.len()).filter(|&t| !tris[t].dead).collect();
        alive.sort_by_cached_key(|&t| {
            let [a, b, c] = tris[t].v.map(|i| p[i]);
            std::cmp::Reverse((b - a).cross(c - a).length_squared().to_bits())
        });
        let (mut group, mut stack) = (vec![usize::MAX; tris.len()], Vec::with_capacity(64));
        for &s in &alive {
            if group[s] == usize::MAX {
                group[s] = s; // a group is named by its first, largest triangle
                stack.push(s);
            }
            while let Some(t) = stack.pop() {
                for u in tris[t].adj {
                    let on_plane = |i: &usize| (tris[s].n.dot(p[*i]) - tris[s].d).abs() <= eps;
                    if group[u] == usize::MAX && tris[u].v.iter().all(on_plane) {
                        group[u] = s;
                        stack.push(u);
                    }
                }
            }
        }
        alive.sort_by_key(|&t| group[t]); // stable: a group's first triangle leads it
        // Each face: its boundary loop `ring[start..end]`, and a normal if it is degenerate.
        let n = alive.len();
        let (mut ring, mut loops, mut edges) = (
            Vec::with_capacity(3 * n),
            Vec::with_capacity(n),
            Vec::with_capacity(32),
        );
        for members in alive.chunk_by(|&x, &y| group[x] == group[y]) {
            let (g, seed) = (group[members[0]], tris[members[0]].n);
            edges.clear();
            for t in members.iter().map(|&t| &tris[t]) {
                let out = (0..3).filter(|&k| group[t.adj[k]] != g);
                edges.extend(out.map(|k| [t.v[k], t.v[(k + 1) % 3], 0]));
            }
            let traced = self.trace(&mut edges);
            let dent = |i: usize| {
                let ([u, v, _], w) = (edges[i], edges[(i + 1) % edges.len()][1]);
                let inward = seed.cross(p[w] - p[u]).normalize_or_zero();
                inward.dot(p[v] - p[u])
            };
            if traced && (0..edges.len()).all(|i| dent(i) <= eps) {
                ring.extend(edges.iter().map(|e| e[0]));
                loops.push((ring.len() - edges.len(), ring.len(), seed));
            } else {
                for t in members.iter().map(|&t| &tris[t]) {
                    ring.extend(t.v);
                    loops.push((ring.len() - 3, ring.len(), t.n));
                }
            }
        }
        // Points on two faces only are dropped; a triangle left with two was between those faces.
        let mut count = vec![0u32; p.len()];
        ring.iter().for_each(|&v| count[v] += 1);
        let (mut vertices, mut faces, mut face_indices, mut edges_out) = (
            Vec::with_capacity(n / 2 + 2),
            Vec::with_capacity(loops.len()),
            Vec::with_capacity(ring.len()),
            Vec::with_capacity(ring.len()),
        );
        let (mut remap, mut face_start, mut kept) = (
            vec![u32::MAX; p.len()],
            Vec::with_capacity(loops.len() + 1),
            Vec::with_capacity(32),
        );
        face_start.push(0);
        for &(start, end, fallback) in &loops {
            kept.clear();
            kept.extend(ring[start..end].iter().copied().filter(|&v| count[v] != 2));
            if kept.len() < 3 {
                continue;
            }
            let k = kept.len();
            let q = |i: usize| self.orig[kept[i % k]].as_dvec3(); // Newell's, in f64: thin faces too
            let c = (0..k).map(q).sum::<DVec3>() / k as f64;
            let area: DVec3 = (0..k).map(|i| (q(i) - c).cross(q(i + 1) - c)).sum();
            let normal = area.try_normalize().map_or(fallback, |n| n.as_vec3());
            let heights = kept.iter().map(|&v| normal.dot(self.orig[v]));
            let offset = heights.fold(f32::MIN, f32::max);
            for &v in &kept {
                if remap[v] == u32::MAX {
                    remap[v] = vertices.len() as u32;
                    vertices.push(self.orig[v]);
                }
            }
            for (i, &v) in kept.iter().enumerate() {
                face_indices.push(remap[v]);
                edges_out.push([remap[v], remap[kept[(i + 1) % k]]]);
            }
            faces.push(HullFace { normal, offset });
            face_start.push(face_indices.len() as u32);
        }
        let solid = faces.len() > 3; // else a thin tetrahedron whose faces merged
        let (neighbours, neighbour_start) = grouped_by_start(&edges_out, vertices.len());
        let hull = ConvexHull {
            lanes: SupportLanes::new(&vertices),
            bounding_radius: vertices.iter().fold(0.0, |r, v| r.max(v.length())),
            inner_radius: length_or_zero(faces.iter().fold(f32::INFINITY, |r, f| r.min(f.offset))),
            vertices,
            faces,
            face_indices,
            face_start,
            neighbours,
            neighbour_start,
        };
        solid.then_some(hull).ok_or(HullError::Degenerate)
    }
}

/// The ends of `edges` grouped by their start (a counting sort, so each start's ends keep their
/// order), with where each start's run begins: `ends[start[v]..start[v + 1]]` for `v` in
/// `0..vertices`.
fn grouped_by_start(edges: &[[u32; 2]], vertices: usize) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; vertices + 1];
    for &[from, _] in edges {
        start[from as usize + 1] += 1;
    }
    for v in 0..vertices {
        start[v + 1] += start[v];
    }
    let (mut next, mut ends) = (start.clone(), vec![0u32; edges.len()]);
    for &[from, to] in edges {
        ends[next[from as usize] as usize] = to;
        next[from as usize] += 1;
    }
    (ends, start)
}

#[cfg(test)]
#[path = "convex_hull_tests.rs"]
mod tests;
#[cfg(test)]
pub(crate) use tests::box_hull;

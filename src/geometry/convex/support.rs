//! Shapes as support functions (the "support mapping" of Gilbert, Johnson & Keerthi 1988 and van
//! den Bergen 2003): for a direction `d`, the point of the shape farthest along `d`. GJK and EPA
//! see a shape only through it, so one pair of algorithms serves every convex pair.
//!
//! Each shape is split into a *core* and a *rounding* radius (van den Bergen's "margin", Box2D's
//! `b2ShapeProxy.radius`): a sphere is a point rounded by its radius, a capsule a segment rounded
//! by its. GJK then runs on the cores, where it converges in a few iterations, and the radii are
//! added back exactly; EPA is only needed when the cores themselves overlap.
//!
//! Besides the support point, a core reports its *supporting feature* along a direction: the
//! face, edge or point that touches a plane pushed against it. The manifold builder clips two
//! features against each other (Gregorius, "Robust contact creation for physics simulations",
//! GDC 2015), so a box resting on a hull gets four points, not one.

use crate::geometry::{ConvexHull, Isometry, Shape, Triangle};
use glam::{Vec2, Vec3};

/// Most points a supporting feature holds. A hull face with more vertices is subsampled evenly
/// (an inscribed polygon: its contact region shrinks slightly, its deepest point stays exact).
pub(crate) const MAX_FEATURE_POINTS: usize = 32;

/// Corners of the polygon standing in for a cylinder's circular cap. The first corner is put at
/// the support direction's azimuth, so the deepest point of a tilted cap is exact.
const CAP_CORNERS: usize = 8;

/// A cap met square on, the direction within this of the axis (sine; 1 mrad), has its corners
/// at fixed angles in the body's frame, numbered. Turned to the direction's azimuth, they
/// turned with the rounding of its few sideways bits: each step other points of the rim, whose
/// friction impulses the warm start matched by place to the last step's others, and a squat
/// cylinder (radius 0.5, half height 0.2) resting on a 30° slope crept 28 mm in 10 s, a cone
/// 144 mm (a user-style probe). Fixed, a corner misses the lowest point of the rim by at most
/// `r (1 − cos(π / 8)) · 1e-3`, 7.6e-5 of the radius.
const FLAT_CAP_SINE: f32 = 1e-3;

/// A cylinder offers its cap as a feature when the direction is at least this close to its
/// axis (cosine; 60°): the cap's lower rim then lies within the region a clip keeps.
const CAP_FEATURE_COSINE: f32 = 0.5;

/// A cylinder's side or a capsule's segment lies flat along the direction's plane when the
/// direction's axial component is at most this (sine, ~3°); a line contact then has two ends.
pub(crate) const LINE_FEATURE_SINE: f32 = 0.05;

/// The inner shape a convex shape is rounded from.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Core<'a> {
    /// The origin (a sphere's centre).
    Point,
    /// The segment from `-half_length` to `+half_length` along z (a capsule's axis).
    Segment(f32),
    /// A box of these half extents.
    Cuboid(Vec3),
    /// A cylinder along z: `(half_height, radius)`.
    Cylinder(f32, f32),
    /// A cone along z, base at `−half_height`, apex at `+half_height`: `(half_height, radius)`.
    Cone(f32, f32),
    /// An ellipsoid of these semi-axes.
    Ellipsoid(Vec3),
    /// A convex polyhedron.
    Hull(&'a ConvexHull),
    /// A triangle (of a mesh), in the part's frame.
    Triangle([Vec3; 3]),
}

/// A convex shape placed in the frame a query works in: its core, its rounding radius, and its
/// pose in that frame.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ConvexPart<'a> {
    pub core: Core<'a>,
    pub rounding: f32,
    pose: Isometry,
    /// [`ConvexPart::size`], found once: a hull's is a pass over its vertices, and every GJK,
    /// EPA and clip of the query reads it.
    size: f32,
    /// Whether `pose` turns (a convex pair's first part sits at the identity: its support
    /// points need no rotation there and back, a fifth of a hull pair's support work). Set
    /// with the pose, which nothing changes afterwards.
    turned: bool,
}

/// The supporting feature of a core along a direction, in the query's frame: its points, and the
/// outward unit normal when the feature is a face.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Feature {
    points: [Vec3; MAX_FEATURE_POINTS],
    len: usize,
    /// Outward unit normal of a face feature; `None` for a point or an edge.
    pub normal: Option<Vec3>,
    /// The feature's number within its shape (a box's or hull's face, a cylinder's cap or side
    /// line; 0 for a single point), which the contact's feature ids are built from.
    pub id: u32,
    /// Whether its corners are numbered in the shape's own frame, the same from step to step
    /// (a box's or hull's face, a side line's ends). A cylinder's cap is not: its polygon
    /// turns with the query's direction, so its corners name no feature.
    pub numbered: bool,
}

/// Feature numbers of the curved shapes' features (a box's faces take 1..=6, a hull's from
/// [`HULL_FACES`]).
const CAP: u32 = 8;
const SIDE_LINE: u32 = 10;
const AXIS_LINE: u32 = 11;
const TRIANGLE_FACE: u32 = 12;
const HULL_FACES: u32 = 16;

impl Feature {
    fn new(normal: Option<Vec3>) -> Self {
        Self {
            points: [Vec3::ZERO; MAX_FEATURE_POINTS],
            len: 0,
            normal,
            id: 0,
            numbered: false,
        }
    }

    /// The feature numbered `id`, its corners numbered in the shape's frame.
    fn named(self, id: u32) -> Self {
        Self {
            id,
            numbered: true,
            ..self
        }
    }

    fn push(&mut self, p: Vec3) {
        if self.len < MAX_FEATURE_POINTS {
            self.points[self.len] = p;
            self.len += 1;
        }
    }

    /// The feature's points, in order around it.
    pub fn points(&self) -> &[Vec3] {
        &self.points[..self.len]
    }

    fn placed(mut self, pose: &Isometry) -> Self {
        for p in &mut self.points[..self.len] {
            *p = pose.transform_point(*p);
        }
        self.normal = self.normal.map(|n| pose.transform_vector(n));
        self
    }
}

/// `+1` for `x >= 0`, `-1` otherwise: ties go the same way every time.
#[inline]
fn sign(x: f32) -> f32 {
    if x >= 0.0 { 1.0 } else { -1.0 }
}

impl<'a> ConvexPart<'a> {
    /// The part of a shape placed at `pose`, or `None` for a half-space or a mesh (not convex
    /// parts: they have their own tests).
    pub fn of_shape(shape: &'a Shape, pose: Isometry) -> Option<Self> {
        let (core, rounding) = match shape {
            Shape::Sphere(s) => (Core::Point, s.radius),
            Shape::Capsule(c) => (Core::Segment(c.half_length), c.radius),
            Shape::Cuboid(c) => (Core::Cuboid(c.half_extents), 0.0),
            Shape::Cylinder(c) => (Core::Cylinder(c.half_height, c.radius), 0.0),
            Shape::Cone(c) => (Core::Cone(c.half_height, c.radius), 0.0),
            Shape::Ellipsoid(e) => (Core::Ellipsoid(e.radii), 0.0),
            Shape::ConvexHull(h) => (Core::Hull(h), 0.0),
            Shape::HalfSpace(_) | Shape::TriMesh(_) => return None,
        };
        Some(Self {
            core,
            rounding,
            pose,
            size: core_size(core) + rounding,
            // Exactly the identity (not `RelativePose::rotation_free`, which also takes
            // -IDENTITY): the case checked to give the rotation's bits.
            turned: pose.rotation != glam::Quat::IDENTITY,
        })
    }

    /// A mesh triangle, in the query's frame.
    pub fn triangle(tri: &Triangle) -> Self {
        let core = Core::Triangle(tri.vertices());
        Self {
            core,
            rounding: 0.0,
            pose: Isometry::IDENTITY,
            size: core_size(core),
            turned: false,
        }
    }

    /// The part's origin (a triangle's centroid): where GJK starts looking. For a hull built
    /// from points far from their origin it may lie outside the core; GJK only needs a start.
    pub fn center(&self) -> Vec3 {
        match self.core {
            Core::Triangle([a, b, c]) => (a + b + c) / 3.0,
            _ => self.pose.translation,
        }
    }

    /// About the core's size plus its rounding: the scale its tolerances are relative to.
    pub fn size(&self) -> f32 {
        self.size
    }

    /// The core's point farthest along `dir` (in the query's frame).
    ///
    /// Always inlined into its one caller, GJK's support of the pair: called, `dir` went
    /// through memory as a 12-byte `Vec3` and the first 8-byte load of it straddled the
    /// caller's two stores (a failed store-to-load forwarding; `perf annotate` put the samples
    /// there). Inlined, a capsule cast at a mesh (a GJK advancement per triangle) runs 12 %
    /// faster for 1.7 % fewer instructions.
    #[inline(always)]
    pub fn support(&self, dir: Vec3) -> Vec3 {
        if !dir.is_finite() {
            // Never walk a hull along a NaN direction; any point of the core answers.
            return self.center();
        }
        if let Core::Triangle(v) = self.core {
            return farthest(&v, dir);
        }
        if !self.turned {
            // What the identity rotation gives, bit for bit: its sums turn a support point's
            // -0 into +0 (so does `+ 0`, before the translation, which may hold a -0). The
            // direction's signs of zero change no support point's value, only, at most, the
            // sign of a zero coordinate, which the same `+ 0` then clears.
            let point = self.local_support(dir + Vec3::ZERO) + Vec3::ZERO;
            return point + self.pose.translation;
        }
        let local = self.pose.inverse_transform_vector(dir);
        self.pose.transform_point(self.local_support(local))
    }

    /// Always inlined into [`support`](Self::support), so that its answer stays in registers
    /// (called, it came back through memory, as `ConvexHull::support_index` explains).
    #[inline(always)]
    fn local_support(&self, d: Vec3) -> Vec3 {
        match self.core {
            Core::Point => Vec3::ZERO,
            Core::Segment(h) => Vec3::new(0.0, 0.0, h * sign(d.z)),
            Core::Cuboid(h) => Vec3::new(h.x * sign(d.x), h.y * sign(d.y), h.z * sign(d.z)),
            Core::Cylinder(h, r) => {
                let radial = Vec2::new(d.x, d.y).normalize_or_zero() * r;
                Vec3::new(radial.x, radial.y, h * sign(d.z))
            }
            Core::Cone(h, r) => {
                // The apex or the base's rim point under `d`, whichever reaches farther (the
                // apex on a tie).
                let (apex, rim) = cone_apex_and_rim(h, r, d);
                if rim.dot(d) > apex.dot(d) { rim } else { apex }
            }
            Core::Ellipsoid(r) => {
                // Where the normal r^-2 ⊙ x is parallel to d on (x/r)² = 1.
                let scaled = r * d;
                let len = scaled.length();
                if len > 0.0 {
                    r * scaled / len
                } else {
                    Vec3::ZERO
                }
            }
            Core::Hull(h) => h.vertices()[h.support_index(d)],
            Core::Triangle(v) => farthest(&v, d),
        }
    }

    /// The core's supporting feature along `dir` (module docs), in the query's frame.
    pub fn feature(&self, dir: Vec3) -> Feature {
        if let Core::Triangle([a, b, c]) = self.core {
            let normal = (b - a).cross(c - a).try_normalize();
            let normal = normal.map(|n| if n.dot(dir) < 0.0 { -n } else { n });
            let mut f = Feature::new(normal).named(TRIANGLE_FACE);
            // Counter-clockwise about the outward normal.
            let flip = normal.is_some_and(|n| (b - a).cross(c - a).dot(n) < 0.0);
            for p in if flip { [a, c, b] } else { [a, b, c] } {
                f.push(p);
            }
            return f;
        }
        let local = self.pose.inverse_transform_vector(dir);
        self.local_feature(local).placed(&self.pose)
    }

    fn local_feature(&self, d: Vec3) -> Feature {
        let single = |p: Vec3| {
            let mut f = Feature::new(None);
            f.push(p);
            f
        };
        let len = d.length();
        match self.core {
            Core::Segment(h) if d.z.abs() <= LINE_FEATURE_SINE * len => {
                let mut f = Feature::new(None).named(AXIS_LINE);
                f.push(Vec3::new(0.0, 0.0, -h));
                f.push(Vec3::new(0.0, 0.0, h));
                f
            }
            Core::Cuboid(h) => box_face(h, d),
            Core::Cylinder(h, r) => cylinder_feature(h, r, d, len),
            Core::Cone(h, r) => cone_feature(h, r, d, len),
            Core::Hull(hull) => hull_face(hull, d),
            _ => single(self.local_support(d)),
        }
    }
}

/// About the size of a core (a half extent, a hull's bounding radius, a triangle's longer
/// first edges).
fn core_size(core: Core) -> f32 {
    match core {
        Core::Point => 0.0,
        Core::Segment(h) => h,
        Core::Cuboid(h) => h.max_element(),
        Core::Cylinder(h, r) | Core::Cone(h, r) => h.max(r),
        Core::Ellipsoid(r) => r.max_element(),
        Core::Hull(h) => h.bounding_radius(),
        Core::Triangle([a, b, c]) => (a - b).length().max((b - c).length()),
    }
}

/// The vertex of `v` farthest along `d` (the first on ties).
fn farthest(v: &[Vec3; 3], d: Vec3) -> Vec3 {
    let mut best = v[0];
    for &p in &v[1..] {
        if p.dot(d) > best.dot(d) {
            best = p;
        }
    }
    best
}

/// The box face most aligned with `d`, counter-clockwise about its outward normal.
fn box_face(h: Vec3, d: Vec3) -> Feature {
    let a = d.abs();
    let i = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    let s = sign(d[i]);
    let (j, k) = ((i + 1) % 3, (i + 2) % 3);
    let mut normal = Vec3::ZERO;
    normal[i] = s;
    let mut f = Feature::new(Some(normal)).named(1 + 2 * i as u32 + u32::from(s > 0.0));
    // (+u +v), (-u +v), (-u -v), (+u -v) turn counter-clockwise about e_j × e_k = e_i; the
    // bottom face (s < 0) runs the other way.
    let corners = [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)];
    for n in 0..4 {
        let (u, v) = corners[if s > 0.0 { n } else { 3 - n }];
        let mut p = Vec3::ZERO;
        p[i] = s * h[i];
        p[j] = u * h[j];
        p[k] = v * h[k];
        f.push(p);
    }
    f
}

/// A cylinder's cap (a polygon with a corner at `d`'s azimuth, or at fixed angles when `d` is
/// square to it: [`FLAT_CAP_SINE`]), its side line, or its support point, by how `d` meets the
/// axis.
fn cylinder_feature(h: f32, r: f32, d: Vec3, len: f32) -> Feature {
    let sideways = Vec2::new(d.x, d.y);
    let radial = sideways.try_normalize().unwrap_or(Vec2::X);
    let s = sign(d.z);
    if d.z.abs() >= CAP_FEATURE_COSINE * len {
        let mut f = Feature::new(Some(Vec3::new(0.0, 0.0, s)));
        f.id = CAP + u32::from(s > 0.0);
        let square = sideways.length() <= FLAT_CAP_SINE * len;
        f.numbered = square;
        let radial = if square { Vec2::X } else { radial };
        for n in 0..CAP_CORNERS {
            let turn = std::f32::consts::TAU * n as f32 / CAP_CORNERS as f32 * s;
            let dir = Vec2::from_angle(turn).rotate(radial) * r;
            f.push(Vec3::new(dir.x, dir.y, s * h));
        }
        return f;
    }
    let rim = radial * r;
    let mut f = Feature::new(None).named(SIDE_LINE);
    if d.z.abs() <= LINE_FEATURE_SINE * len {
        f.push(Vec3::new(rim.x, rim.y, -h));
        f.push(Vec3::new(rim.x, rim.y, h));
    } else {
        f.push(Vec3::new(rim.x, rim.y, s * h));
    }
    f
}

/// A cone's apex and the point of its base's rim under `d`'s azimuth (any rim point when `d`
/// is along the axis).
fn cone_apex_and_rim(h: f32, r: f32, d: Vec3) -> (Vec3, Vec3) {
    let radial = Vec2::new(d.x, d.y).try_normalize().unwrap_or(Vec2::X) * r;
    (Vec3::new(0.0, 0.0, h), Vec3::new(radial.x, radial.y, -h))
}

/// A cone's base (a polygon, as a cylinder's cap) when `d` points down its axis, the side line
/// from the rim to the apex when `d` is square to that line, else its support point.
fn cone_feature(h: f32, r: f32, d: Vec3, len: f32) -> Feature {
    if -d.z >= CAP_FEATURE_COSINE * len {
        // The bottom cap of a cylinder of the same height and radius.
        return cylinder_feature(h, r, d, len);
    }
    let (apex, rim) = cone_apex_and_rim(h, r, d);
    let mut f = Feature::new(None).named(SIDE_LINE);
    // `d` lies in the plane of its azimuth, as the side line does: the line supports the cone
    // when `d` is nearly square to it and points out of the cone.
    let along = (apex - rim).try_normalize().map_or(1.0, |s| s.dot(d).abs());
    let outward = Vec3::new(rim.x, rim.y, 0.0) * (2.0 * h) + Vec3::Z * (r * r);
    if along <= LINE_FEATURE_SINE * len && outward.dot(d) > 0.0 {
        f.push(rim);
        f.push(apex);
    } else {
        f.push(if rim.dot(d) > apex.dot(d) { rim } else { apex });
    }
    f
}

/// The hull face most aligned with `d`; a face of more than [`MAX_FEATURE_POINTS`] corners is
/// subsampled evenly.
fn hull_face(hull: &ConvexHull, d: Vec3) -> Feature {
    let face = hull.best_face(d);
    let normal = hull.faces().get(face).map(|f| f.normal);
    let mut f = Feature::new(normal).named(HULL_FACES + face as u32);
    let ids = hull.face_vertices(face);
    let step = ids.len().div_ceil(MAX_FEATURE_POINTS).max(1);
    for &i in ids.iter().step_by(step) {
        if let Some(&p) = hull.vertices().get(i as usize) {
            f.push(p);
        }
    }
    if f.len == 0 {
        f.push(hull.support(d));
    }
    f
}

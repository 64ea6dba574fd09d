//! Mass properties of shapes: mass, centre of mass and inertia tensor, placed and combined.
//!
//! - **Sphere and box**: closed forms, `I = 2/5 m r²` and `I_xx = m/12 (b² + c²)` (b, c the
//!   box's sizes along the other two axes).
//! - **Capsule** (along z, half length `h`, radius `r`): a cylinder of length `2h` and a ball
//!   split into two caps. About the axis `I_zz = m_c r²/2 + 2/5 m_b r²`; across it each cap is a
//!   half ball whose centre sits `3r/8` beyond its flat face, moved to the capsule's centre by the
//!   parallel-axis theorem, which sums to `I_xx = m_c (r²/4 + h²/3) + m_b (2/5 r² + h² + 3/4 h r)`.
//! - **Cylinder** (along z) and **ellipsoid**: closed forms, `I_zz = m r²/2`,
//!   `I_xx = m (3r² + L²)/12` and `I_xx = m (b² + c²)/5`. A **convex hull** is integrated as the
//!   closed mesh of its faces (next item).
//! - **Closed triangle meshes**: the volume integrals of Mirtich ("Fast and Accurate Computation
//!   of Polyhedral Mass Properties", 1996) in the form of Eberly ("Polyhedral Mass Properties
//!   (Revisited)", 2002): the divergence theorem turns the ten integrals of `1, x, y, z, x², y²,
//!   z², xy, yz, zx` over the solid into sums over its triangles. They are accumulated in `f64`
//!   with the vertices first moved so that the mesh's bounding-box centre is the origin, so a
//!   mesh far from its local origin keeps its digits. An inward-oriented mesh (negative volume)
//!   has every integral's sign flipped.
//! - **Open meshes and flat ones** (not every edge shared by exactly two triangles running it in
//!   opposite directions, see `is_closed` — or a signed volume below `1e-6 · d³`, `d` the
//!   bounding-box diagonal: a sheet, a single triangle, a double-sided quad): the surface is a
//!   **thin shell** of thickness [`MassProperties::SHELL_THICKNESS_FRACTION`]` · d`, so its mass
//!   is `density · area · thickness`, its centre the area centroid, and each triangle adds the
//!   second moment `A/12 (Σ vᵢvᵢᵀ + s sᵀ)` (`s` the sum of its corners; the shell's own
//!   thickness is neglected). Any mesh urto accepts has non-zero area, so this never gives a
//!   NaN or a zero tensor.
//! - **Placement and combination**: a tensor moves to a parent frame as `R I Rᵀ`, and parts are
//!   combined about their mass-weighted centre with the parallel-axis theorem
//!   `I_O = I_C + m (|d|² E − d dᵀ)` (Huygens–Steiner), in `f64`.
//!
//! Tensors are about the centre of mass, in the shape's local axes, with the usual sign
//! convention (off-diagonal entries are `−∫ρ xy`).

use crate::bounding::symmetric_eigen::symmetric_eigen;
use crate::geometry::{ConvexHull, Isometry, Shape, TriMesh};
use glam::{DMat3, DQuat, DVec3, Mat3, Quat, Vec3};

/// Mass, centre of mass and inertia tensor (about the centre of mass, in the shape's local axes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProperties {
    /// Kilograms; `f32::INFINITY` for unbounded shapes.
    pub mass: f32,
    /// The centre of mass in the shape's local frame.
    pub local_center_of_mass: Vec3,
    /// Symmetric inertia tensor (kg·m²) about the centre of mass, in the local axes.
    pub inertia: Mat3,
}

/// A closed mesh whose |signed volume| is below this fraction of its bounding-box diagonal cubed
/// is flat: it gets the thin-shell fallback.
const FLAT_VOLUME_FRACTION: f64 = 1e-6;

impl MassProperties {
    /// No mass: a shape of zero volume, and the identity of [`compound`](Self::compound).
    pub const ZERO: Self = Self::new(0.0, Vec3::ZERO, Mat3::ZERO);

    /// From its three parts (the tensor about the centre of mass, in the local axes).
    pub const fn new(mass: f32, local_center_of_mass: Vec3, inertia: Mat3) -> Self {
        Self {
            mass,
            local_center_of_mass,
            inertia,
        }
    }

    /// Thickness of the thin shell that stands for an open or flat mesh, as a fraction of the
    /// mesh's bounding-box diagonal (see the module notes).
    pub const SHELL_THICKNESS_FRACTION: f32 = 0.01;

    /// Infinite mass and inertia (a half-space), centred on the origin; its tensor is
    /// `diag(∞, ∞, ∞)` with zero off-diagonal entries.
    ///
    /// [`transformed`](Self::transformed) only moves its centre; a [`compound`](Self::compound)
    /// with an infinite part is infinite; [`inverse_inertia`](Self::inverse_inertia) is zero
    /// and [`principal`](Self::principal) gives `(∞, ∞, ∞)` with the identity rotation.
    pub fn infinite() -> Self {
        Self::infinite_at(Vec3::ZERO)
    }

    fn infinite_at(centre: Vec3) -> Self {
        Self::new(f32::INFINITY, centre, Mat3::from_diagonal(Vec3::INFINITY))
    }

    /// From `f64` values, with the symmetric part of the tensor (rounding never leaves it
    /// asymmetric).
    fn from_f64(mass: f64, centre: DVec3, inertia: DMat3) -> Self {
        let inertia = (inertia + inertia.transpose()) * 0.5;
        Self::new(mass as f32, centre.as_vec3(), inertia.as_mat3())
    }

    fn centre_f64(&self) -> DVec3 {
        self.local_center_of_mass.as_dvec3()
    }

    /// True when the mass or the tensor is not finite (as for [`infinite`](Self::infinite)).
    pub fn is_infinite(&self) -> bool {
        !self.mass.is_finite() || !self.inertia.is_finite()
    }

    /// A solid ball of `radius` and `density` (kg/m³), centred on the origin.
    pub fn sphere(radius: f32, density: f32) -> Self {
        let r = radius as f64;
        let mass = 4.0 / 3.0 * std::f64::consts::PI * r * r * r * density as f64;
        let tensor = DMat3::from_diagonal(DVec3::splat(0.4 * mass * r * r));
        Self::from_f64(mass, DVec3::ZERO, tensor)
    }

    /// A solid box of `half_extents` and `density` (kg/m³), centred on the origin.
    pub fn cuboid(half_extents: Vec3, density: f32) -> Self {
        let h = half_extents.as_dvec3();
        let mass = 8.0 * h.x * h.y * h.z * density as f64;
        let s = h * h;
        let moments = DVec3::new(s.y + s.z, s.z + s.x, s.x + s.y) * (mass / 3.0);
        Self::from_f64(mass, DVec3::ZERO, DMat3::from_diagonal(moments))
    }

    /// A solid capsule along z (see the module notes) of `half_length`, `radius` and `density`
    /// (kg/m³), centred on the origin.
    pub fn capsule(half_length: f32, radius: f32, density: f32) -> Self {
        let (h, r, rho) = (half_length as f64, radius as f64, density as f64);
        let pi = std::f64::consts::PI;
        let cylinder = pi * r * r * 2.0 * h * rho;
        let ball = 4.0 / 3.0 * pi * r * r * r * rho;
        let axial = cylinder * r * r / 2.0 + ball * 0.4 * r * r;
        let across =
            cylinder * (r * r / 4.0 + h * h / 3.0) + ball * (0.4 * r * r + h * h + 0.75 * h * r);
        let tensor = DMat3::from_diagonal(DVec3::new(across, across, axial));
        Self::from_f64(cylinder + ball, DVec3::ZERO, tensor)
    }

    /// A solid cylinder along z of `half_height`, `radius` and `density` (kg/m³), centred on
    /// the origin: `I_z = m r²/2`, `I_x = I_y = m (3r² + (2h)²)/12`.
    pub fn cylinder(half_height: f32, radius: f32, density: f32) -> Self {
        let (h, r) = (half_height as f64, radius as f64);
        let mass = std::f64::consts::PI * r * r * 2.0 * h * density as f64;
        let across = mass * (3.0 * r * r + 4.0 * h * h) / 12.0;
        let tensor = DMat3::from_diagonal(DVec3::new(across, across, mass * r * r / 2.0));
        Self::from_f64(mass, DVec3::ZERO, tensor)
    }

    /// A solid cone along z ([`Cone`](crate::geometry::Cone): base at `−half_height`, apex at
    /// `+half_height`) of `radius` and `density` (kg/m³): `m = π r² (2h) ρ / 3`, its centre of
    /// mass at `z = −h/2` (a quarter of the height above the base), and about it
    /// `I_z = 3 m r²/10`, `I_x = I_y = 3 m (r²/20 + (2h)²/80) = 3 m (r² + h²)/20`.
    pub fn cone(half_height: f32, radius: f32, density: f32) -> Self {
        let (h, r) = (half_height as f64, radius as f64);
        let mass = std::f64::consts::PI * r * r * 2.0 * h * density as f64 / 3.0;
        let across = 3.0 * mass * (r * r + h * h) / 20.0;
        let tensor = DMat3::from_diagonal(DVec3::new(across, across, 0.3 * mass * r * r));
        Self::from_f64(mass, DVec3::new(0.0, 0.0, -h / 2.0), tensor)
    }

    /// A solid ellipsoid of semi-axes `radii` and `density` (kg/m³), centred on the origin:
    /// `m = 4/3 π abc ρ`, `I_x = m (b² + c²)/5` and so on.
    pub fn ellipsoid(radii: Vec3, density: f32) -> Self {
        let r = radii.as_dvec3();
        let mass = 4.0 / 3.0 * std::f64::consts::PI * r.x * r.y * r.z * density as f64;
        let s = r * r;
        let moments = DVec3::new(s.y + s.z, s.z + s.x, s.x + s.y) * (mass / 5.0);
        Self::from_f64(mass, DVec3::ZERO, DMat3::from_diagonal(moments))
    }

    /// A solid convex hull at `density` (kg/m³): its faces fanned into a closed mesh and
    /// integrated as one (Mirtich 1996, as [`trimesh`](Self::trimesh)).
    pub fn convex_hull(hull: &ConvexHull, density: f32) -> Self {
        match hull.to_trimesh() {
            Ok(mesh) => Self::trimesh(&mesh, density),
            // A built hull always has faces; keep the promise of no panic regardless.
            Err(_) => Self::ZERO,
        }
    }

    /// A triangle mesh at `density` (kg/m³): the enclosed solid if the mesh is closed and has
    /// volume, otherwise a thin shell (see the module notes).
    pub fn trimesh(mesh: &TriMesh, density: f32) -> Self {
        let aabb = mesh.local_aabb();
        let origin = aabb.center().as_dvec3();
        let diagonal = aabb.extents().as_dvec3().length();
        if is_closed(mesh) {
            let solid = volume_moments(mesh, origin);
            if solid.zeroth.abs() > FLAT_VOLUME_FRACTION * diagonal.powi(3) {
                // An inward-oriented mesh has every integral negated.
                let density = density as f64 * solid.zeroth.signum();
                return solid.to_mass_properties(origin, density);
            }
        }
        let thickness = Self::SHELL_THICKNESS_FRACTION as f64 * diagonal;
        shell_moments(mesh, origin).to_mass_properties(origin, density as f64 * thickness)
    }

    /// The same distribution scaled to `mass` (the centre does not move, the tensor is scaled by
    /// `mass / self.mass`).
    ///
    /// With `mass == ∞` the result is infinite (see [`infinite`](Self::infinite)) at the same
    /// centre. When `self` has no finite positive mass (zero, infinite) there is no
    /// distribution to scale: the result has `mass` and keeps `self.inertia` unchanged (zero for
    /// [`ZERO`](Self::ZERO)), never a NaN. So compute a shape at density 1, then set its mass.
    pub fn with_mass(self, mass: f32) -> Self {
        if mass == f32::INFINITY {
            return Self::infinite_at(self.local_center_of_mass);
        }
        let inertia = if self.mass.is_finite() && self.mass > 0.0 {
            (self.inertia.as_dmat3() * (mass as f64 / self.mass as f64)).as_mat3()
        } else {
            self.inertia
        };
        Self::new(mass, self.local_center_of_mass, inertia)
    }

    /// The same body expressed in the parent frame of `pose`: the centre is carried by the
    /// pose, the tensor rotated to `R I Rᵀ` (a non-finite tensor is kept as is).
    pub fn transformed(&self, pose: &Isometry) -> Self {
        let local_center_of_mass = pose.transform_point(self.local_center_of_mass);
        if !self.inertia.is_finite() {
            return Self::new(self.mass, local_center_of_mass, self.inertia);
        }
        let r = DMat3::from_quat(pose.rotation.as_dquat().normalize());
        let inertia = r * self.inertia.as_dmat3() * r.transpose();
        Self::from_f64(self.mass as f64, local_center_of_mass.as_dvec3(), inertia)
    }

    /// The rigid union of `parts`, each placed in the compound's frame by its pose: total mass,
    /// mass-weighted centre, and the parts' tensors moved there by the parallel-axis theorem.
    ///
    /// No parts (or only massless ones) give [`ZERO`](Self::ZERO)-mass properties (massless
    /// parts still add their tensors). A part with infinite mass or a non-finite tensor makes
    /// the compound [`infinite`](Self::infinite), centred on the mean of the infinite parts'
    /// centres (a mass-weighted mean is undefined).
    pub fn compound(parts: impl IntoIterator<Item = (Isometry, MassProperties)>) -> Self {
        let placed: Vec<Self> = parts.into_iter().map(|(p, m)| m.transformed(&p)).collect();
        let infinite: Vec<DVec3> = placed
            .iter()
            .filter(|p| p.is_infinite())
            .map(Self::centre_f64)
            .collect();
        if !infinite.is_empty() {
            let centre = infinite.iter().sum::<DVec3>() / infinite.len() as f64;
            return Self::infinite_at(centre.as_vec3());
        }
        let mass: f64 = placed.iter().map(|p| p.mass as f64).sum();
        let weighted: DVec3 = placed.iter().map(|p| p.centre_f64() * p.mass as f64).sum();
        // Massless parts only: the weighted sum is zero, and so is the centre.
        let centre = weighted / mass.max(f64::MIN_POSITIVE);
        let mut inertia = DMat3::ZERO;
        for p in &placed {
            let d = p.centre_f64() - centre;
            let shift = DMat3::from_diagonal(DVec3::splat(d.length_squared())) - outer(d, d);
            inertia += p.inertia.as_dmat3() + shift * p.mass as f64;
        }
        Self::from_f64(mass, centre, inertia)
    }

    /// Principal moments, in increasing order, and the rotation `R` from the principal axes to
    /// the local axes (`I = R diag(moments) Rᵀ`; column `i` of `R` is the axis of moment `i`).
    ///
    /// By cyclic Jacobi in `f64`, so the axes stay orthonormal for repeated moments (spheres,
    /// cubes). Negative moments and moments below `f32::EPSILON` times the largest (rounding
    /// noise of an `f32` tensor) are returned as 0. A non-finite tensor gives its diagonal and
    /// the identity.
    pub fn principal(&self) -> (Vec3, Quat) {
        if !self.inertia.is_finite() {
            let i = self.inertia.to_cols_array_2d();
            return (Vec3::new(i[0][0], i[1][1], i[2][2]), Quat::IDENTITY);
        }
        let (moments, axes) = principal_f64(self.inertia.as_dmat3());
        let rotation = DQuat::from_mat3(&axes).normalize().as_quat();
        (moments.as_vec3(), rotation)
    }

    /// The inverse tensor, safe to use in the world: zero for an infinite body and zero along
    /// principal axes of zero (or noise-level, see [`principal`](Self::principal)) moment, so it
    /// never holds a NaN or an infinity.
    pub fn inverse_inertia(&self) -> Mat3 {
        if self.is_infinite() {
            return Mat3::ZERO;
        }
        let (moments, axes) = principal_f64(self.inertia.as_dmat3());
        // 1/m where an f32 tensor holds it (with room for the sum of three terms), else 0.
        let smallest = 4.0 / f32::MAX as f64;
        let inverse = moments.map(|m| if m > smallest { 1.0 / m } else { 0.0 });
        let inverse = axes * DMat3::from_diagonal(inverse) * axes.transpose();
        Self::from_f64(0.0, DVec3::ZERO, inverse).inertia
    }
}

impl Shape {
    /// Mass properties at `density` (kg/m³): sphere, cuboid, capsule, cylinder, cone, ellipsoid,
    /// convex hull, half-space (infinite), triangle mesh (solid if closed, else a thin shell: see [`MassProperties::trimesh`]).
    pub fn mass_properties(&self, density: f32) -> MassProperties {
        match self {
            Self::Sphere(s) => MassProperties::sphere(s.radius, density),
            Self::Cuboid(c) => MassProperties::cuboid(c.half_extents, density),
            Self::HalfSpace(_) => MassProperties::infinite(),
            Self::Capsule(c) => MassProperties::capsule(c.half_length, c.radius, density),
            Self::Cylinder(c) => MassProperties::cylinder(c.half_height, c.radius, density),
            Self::Cone(c) => MassProperties::cone(c.half_height, c.radius, density),
            Self::Ellipsoid(e) => MassProperties::ellipsoid(e.radii, density),
            Self::ConvexHull(h) => MassProperties::convex_hull(h, density),
            Self::TriMesh(m) => MassProperties::trimesh(m.mesh(), density),
        }
    }
}

/// True when every edge is shared by exactly two triangles that run it in opposite directions
/// (a closed, consistently oriented surface). Vertices at exactly the same position count as
/// one, so unwelded meshes (one vertex per triangle corner, as STL gives) are recognised too.
pub(crate) fn is_closed(mesh: &TriMesh) -> bool {
    let canonical = mesh.position_ids();
    let mut edges = Vec::with_capacity(3 * mesh.triangle_count());
    for t in mesh.triangles() {
        let c = t.map(|i| canonical[i as usize]);
        for k in 0..3 {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            if a == b {
                return false;
            }
            edges.push((a.min(b), a.max(b), a < b));
        }
    }
    edges.sort_unstable();
    edges
        .chunk_by(|x, y| (x.0, x.1) == (y.0, y.1))
        .all(|g| g.len() == 2 && g[0].2 != g[1].2)
}

/// Unit-density integrals about a reference point: `∫1`, `∫x`, `∫x xᵀ`.
#[derive(Clone, Copy, Debug)]
struct Moments {
    zeroth: f64,
    first: DVec3,
    second: DMat3,
}

impl Moments {
    /// Mass properties at `density`, the moments having been taken about `origin`.
    fn to_mass_properties(self, origin: DVec3, density: f64) -> MassProperties {
        if self.zeroth == 0.0 {
            return MassProperties::from_f64(0.0, origin, DMat3::ZERO);
        }
        let c = self.first / self.zeroth;
        let central = self.second - outer(c, c) * self.zeroth;
        let trace = central.x_axis.x + central.y_axis.y + central.z_axis.z;
        let inertia = (DMat3::from_diagonal(DVec3::splat(trace)) - central) * density;
        MassProperties::from_f64(self.zeroth * density, origin + c, inertia)
    }
}

/// The triangles' corners in `f64`, relative to `origin`.
fn corners(mesh: &TriMesh, origin: DVec3) -> impl Iterator<Item = [DVec3; 3]> + '_ {
    let v = mesh.vertices();
    mesh.triangles()
        .iter()
        .map(move |t| t.map(|i| v[i as usize].as_dvec3() - origin))
}

/// Eberly's subexpressions of one coordinate's values at the three corners:
/// `(f1, f2, f3, [g0, g1, g2])`.
fn subexpressions(w0: f64, w1: f64, w2: f64) -> (f64, f64, f64, [f64; 3]) {
    let temp0 = w0 + w1;
    let f1 = temp0 + w2;
    let temp1 = w0 * w0;
    let temp2 = temp1 + w1 * temp0;
    let f2 = temp2 + w2 * f1;
    let f3 = w0 * temp1 + w1 * temp2 + w2 * f2;
    let g = [w0, w1, w2].map(|w| f2 + w * (f1 + w));
    (f1, f2, f3, g)
}

/// The signed volume integrals of the solid bounded by the mesh (Eberly 2002), about `origin`.
fn volume_moments(mesh: &TriMesh, origin: DVec3) -> Moments {
    // 1, x, y, z, x², y², z², xy, yz, zx.
    let mut s = [0.0f64; 10];
    for [p0, p1, p2] in corners(mesh, origin) {
        let d = (p1 - p0).cross(p2 - p0);
        let (f1x, f2x, f3x, gx) = subexpressions(p0.x, p1.x, p2.x);
        let (_, f2y, f3y, gy) = subexpressions(p0.y, p1.y, p2.y);
        let (_, f2z, f3z, gz) = subexpressions(p0.z, p1.z, p2.z);
        s[0] += d.x * f1x;
        s[1] += d.x * f2x;
        s[2] += d.y * f2y;
        s[3] += d.z * f2z;
        s[4] += d.x * f3x;
        s[5] += d.y * f3y;
        s[6] += d.z * f3z;
        s[7] += d.x * (p0.y * gx[0] + p1.y * gx[1] + p2.y * gx[2]);
        s[8] += d.y * (p0.z * gy[0] + p1.z * gy[1] + p2.z * gy[2]);
        s[9] += d.z * (p0.x * gz[0] + p1.x * gz[1] + p2.x * gz[2]);
    }
    let (xx, yy, zz) = (s[4] / 60.0, s[5] / 60.0, s[6] / 60.0);
    let (xy, yz, zx) = (s[7] / 120.0, s[8] / 120.0, s[9] / 120.0);
    let second = DMat3::from_cols_array(&[xx, xy, zx, xy, yy, yz, zx, yz, zz]);
    let (zeroth, first) = (s[0] / 6.0, DVec3::new(s[1], s[2], s[3]) / 24.0);
    Moments {
        zeroth,
        first,
        second,
    }
}

/// The surface integrals of the mesh (unit area density), about `origin`.
fn shell_moments(mesh: &TriMesh, origin: DVec3) -> Moments {
    let (zeroth, first, second) = (0.0, DVec3::ZERO, DMat3::ZERO);
    let mut m = Moments {
        zeroth,
        first,
        second,
    };
    for [a, b, c] in corners(mesh, origin) {
        let area = 0.5 * (b - a).cross(c - a).length();
        let s = a + b + c;
        m.zeroth += area;
        m.first += s * (area / 3.0);
        m.second += (outer(a, a) + outer(b, b) + outer(c, c) + outer(s, s)) * (area / 12.0);
    }
    m
}

/// `a bᵀ`.
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// Increasing principal moments (noise and negatives clamped to 0) and a proper rotation whose
/// columns are their axes.
fn principal_f64(inertia: DMat3) -> (DVec3, DMat3) {
    let e = symmetric_eigen(inertia);
    let mut order = [0, 1, 2];
    order.sort_by(|&a, &b| e.values[a].total_cmp(&e.values[b]));
    let largest = e.values.max_element().max(0.0);
    let floor = largest * f32::EPSILON as f64;
    let moments = order.map(|i| {
        if e.values[i] > floor {
            e.values[i]
        } else {
            0.0
        }
    });
    let mut cols = order.map(|i| e.vectors.col(i));
    if cols[0].cross(cols[1]).dot(cols[2]) < 0.0 {
        cols[2] = -cols[2];
    }
    let axes = DMat3::from_cols(cols[0], cols[1], cols[2]);
    (DVec3::from(moments), axes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn max_abs(m: Mat3) -> f32 {
        m.abs().to_cols_array().into_iter().fold(0.0, f32::max)
    }

    #[track_caller]
    fn assert_close(a: Mat3, b: Mat3, tol: f32) {
        assert!(max_abs(a - b) <= tol * max_abs(b).max(1e-30), "{a} vs {b}");
    }

    fn cuboid(h: Vec3) -> MassProperties {
        MassProperties::cuboid(h, 1.0)
    }

    #[test]
    fn sphere_and_box_match_the_closed_forms() {
        let s = MassProperties::sphere(2.0, 3.0);
        let m = 4.0 / 3.0 * std::f32::consts::PI * 8.0 * 3.0;
        assert!((s.mass - m).abs() < 1e-6 * m);
        let ball = Mat3::from_diagonal(Vec3::splat(0.4 * m * 4.0));
        assert_close(s.inertia, ball, 1e-6);
        // Sizes 1 × 2 × 3 at density 2: m/12 (b² + c²).
        let b = MassProperties::cuboid(Vec3::new(0.5, 1.0, 1.5), 2.0);
        let m = 12.0;
        assert_eq!(b.mass, m);
        let expected = Vec3::new(4.0 + 9.0, 9.0 + 1.0, 1.0 + 4.0) * (m / 12.0);
        assert_close(b.inertia, Mat3::from_diagonal(expected), 1e-6);
    }

    #[test]
    fn two_half_boxes_make_the_whole_box_and_zero_is_the_identity() {
        let half = cuboid(Vec3::new(0.5, 2.0, 3.0));
        let parts = [-0.5, 0.5].map(|x| (Isometry::from_translation(Vec3::X * x), half));
        let whole = MassProperties::compound(parts);
        let expected = cuboid(Vec3::new(1.0, 2.0, 3.0));
        assert!((whole.mass - expected.mass).abs() < 1e-6 * expected.mass);
        assert!(whole.local_center_of_mass.length() < 1e-6);
        assert_close(whole.inertia, expected.inertia, 1e-6);
        let zero = (parts[0].0, MassProperties::ZERO);
        assert_eq!(MassProperties::compound([parts[0], parts[1], zero]), whole);
        assert_eq!(MassProperties::compound([]), MassProperties::ZERO);
    }

    #[test]
    fn transformed_then_back_is_the_identity() {
        let b = cuboid(Vec3::new(0.3, 1.0, 2.0));
        let rotation = Quat::from_euler(glam::EulerRot::XYZ, 0.4, -1.2, 2.0);
        let pose = Isometry::new(Vec3::new(10.0, -4.0, 2.5), rotation);
        let moved = b.transformed(&pose);
        assert!((moved.local_center_of_mass - pose.translation).length() < 1e-5);
        assert!(max_abs(moved.inertia - b.inertia) > 0.1);
        let back = moved.transformed(&pose.inverse());
        assert!(back.local_center_of_mass.length() < 1e-5);
        assert_close(back.inertia, b.inertia, 1e-6);
    }

    #[test]
    fn principal_recovers_the_moments_and_axes_of_a_rotated_box() {
        let b = cuboid(Vec3::new(1.0, 2.0, 3.0));
        let q = Quat::from_axis_angle(Vec3::new(1.0, 2.0, -0.5).normalize(), 0.9);
        let rotated = b.transformed(&Isometry::new(Vec3::ZERO, q));
        let (moments, r) = rotated.principal();
        let expected = Vec3::new(5.0, 10.0, 13.0) * (b.mass / 3.0);
        let error = (moments - expected).abs().max_element();
        assert!(error < 1e-5 * expected.z, "{moments}");
        let r = Mat3::from_quat(r);
        for (i, local) in [Vec3::Z, Vec3::Y, Vec3::X].into_iter().enumerate() {
            assert!((r.col(i).dot(q * local).abs() - 1.0).abs() < 1e-5);
        }
        let rebuilt = r * Mat3::from_diagonal(moments) * r.transpose();
        assert_close(rebuilt, rotated.inertia, 1e-6);
    }

    #[test]
    fn with_mass_scales_the_tensor_and_never_makes_a_nan() {
        let s = MassProperties::sphere(1.0, 1.0).transformed(&Isometry::from_translation(Vec3::X));
        let heavy = s.with_mass(10.0);
        assert_eq!(heavy.local_center_of_mass, s.local_center_of_mass);
        assert_eq!(heavy.mass, 10.0);
        assert_close(heavy.inertia, Mat3::from_diagonal(Vec3::splat(4.0)), 1e-6);
        let zero = MassProperties::ZERO.with_mass(3.0);
        assert_eq!((zero.mass, zero.inertia), (3.0, Mat3::ZERO));
        let infinite = MassProperties::infinite().with_mass(2.0);
        assert!(infinite.mass == 2.0 && !infinite.inertia.is_nan());
        assert!(s.with_mass(f32::INFINITY).is_infinite());
    }

    #[test]
    fn inverse_of_infinite_zero_and_degenerate_is_finite() {
        let (ball, infinite) = (MassProperties::sphere(1.0, 1.0), MassProperties::infinite());
        let turned = Isometry::new(Vec3::X, Quat::from_rotation_z(1.0));
        for p in [
            infinite,
            MassProperties::ZERO,
            MassProperties::sphere(0.0, 1.0),
            infinite.transformed(&turned),
            MassProperties::compound([(turned, infinite), (turned.inverse(), ball)]),
        ] {
            assert_eq!(p.inverse_inertia(), Mat3::ZERO, "{p:?}");
            let (moments, r) = p.principal();
            assert!(!moments.is_nan() && r.is_finite());
        }
        // Two point masses on the x axis: no moment about x, so no inverse along x.
        let point = MassProperties::ZERO.with_mass(1.0);
        let pair = [-1.0, 1.0].map(|x| (Isometry::from_translation(Vec3::X * x), point));
        let inverse = MassProperties::compound(pair).inverse_inertia();
        assert!(inverse.is_finite() && inverse.x_axis.x == 0.0);
        assert!((inverse.y_axis.y - 0.5).abs() < 1e-6);
        let b = cuboid(Vec3::ONE);
        assert_close(b.inverse_inertia() * b.inertia, Mat3::IDENTITY, 1e-6);
    }

    #[test]
    fn closed_means_every_edge_twice_in_opposite_directions() {
        let mesh = TriMesh::cuboid(Vec3::ONE).unwrap();
        assert!(is_closed(&mesh));
        let (v, t) = (mesh.vertices().to_vec(), mesh.triangles());
        let open = TriMesh::new(v.clone(), t[1..].to_vec()).unwrap();
        assert!(!is_closed(&open));
        let mut one_flipped = t.to_vec();
        one_flipped[0] = [t[0][0], t[0][2], t[0][1]];
        assert!(!is_closed(&TriMesh::new(v.clone(), one_flipped).unwrap()));
        let mut twice = t.to_vec();
        twice.extend_from_slice(&t[..2]);
        assert!(!is_closed(&TriMesh::new(v, twice).unwrap()));
    }
}

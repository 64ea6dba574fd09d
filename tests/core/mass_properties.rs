//! Mass properties against parry3d 0.31's (another implementation: signed tetrahedra from the
//! vertex mean, summed in `f32`): spheres, boxes, closed procedural meshes rotated and moved far
//! from the origin, the real PyVista meshes (both orientations), and an L-shaped compound; an
//! open mesh's thin-shell fallback; and the convergence of a UV sphere's inertia to the ball's.
//! Meshes are also checked against an `f64` tetrahedron sum. Each test prints its worst errors.
//!
//! Full tensors are compared with parry's own tensor (for meshes, summed here with parry's
//! public `details` functions exactly as `from_trimesh` does, before it diagonalises it):
//! parry's `reconstruct_inertia_matrix` goes through its `f32` closed-form eigensolver, whose
//! eigenvectors for nearly equal moments (a sphere) are off by up to the moments' relative gap
//! (4e-3 on `sphere.ply`), and whose eigenvalues for two equal moments (a torus) are off by up
//! to 7e-5, hence the looser bound on principal moments.

use glam::{DMat3, DVec3, Mat3, Quat, Vec3};
use parry3d::mass_properties::MassProperties as ParryMass;
use parry3d::math::Pose;
use parry3d::shape::Shape as _;
use std::path::Path;
use urto::geometry::mesh_io::load_ply;
use urto::geometry::{Isometry, MassProperties, Shape, TriMesh};

/// Relative differences from parry: mass; centre (relative to `size`); full tensor (relative
/// to its largest entry); sorted principal moments (relative to the largest); and the tensor's
/// difference from the `f64` reference when there is one.
#[derive(Clone, Copy, Debug, Default)]
struct Errors {
    mass: f32,
    centre: f32,
    tensor: f32,
    moments: f32,
    reference: f32,
}

/// Largest entry of `a - b` over the largest entry of `b`.
fn relative(a: DMat3, b: DMat3) -> f32 {
    let scale = b.abs().to_cols_array().into_iter().fold(0.0, f64::max);
    let diff = (a - b)
        .abs()
        .to_cols_array()
        .into_iter()
        .fold(0.0, f64::max);
    (diff / scale) as f32
}

impl Errors {
    fn of(
        ours: &MassProperties,
        parry: &ParryMass,
        parry_tensor: Mat3,
        size: f32,
        reference: Option<DMat3>,
    ) -> Self {
        let mut principal = parry.principal_inertia().to_array();
        principal.sort_by(f32::total_cmp);
        let moments = (ours.principal().0 - Vec3::from(principal))
            .abs()
            .max_element();
        let tensor = ours.inertia.as_dmat3();
        Self {
            mass: (ours.mass - parry.mass()).abs() / parry.mass(),
            centre: (ours.local_center_of_mass - parry.local_com).length() / size,
            tensor: relative(tensor, parry_tensor.as_dmat3()),
            moments: moments / principal[2],
            reference: reference.map_or(0.0, |r| relative(tensor, r)),
        }
    }

    /// Against parry's shape, whose tensor is diagonal or well separated.
    fn of_shape(ours: &MassProperties, parry: &ParryMass, size: f32) -> Self {
        Self::of(ours, parry, parry.reconstruct_inertia_matrix(), size, None)
    }

    fn worst(self, o: Self) -> Self {
        Self {
            mass: self.mass.max(o.mass),
            centre: self.centre.max(o.centre),
            tensor: self.tensor.max(o.tensor),
            moments: self.moments.max(o.moments),
            reference: self.reference.max(o.reference),
        }
    }

    /// The largest error but that of the principal moments.
    fn max(&self) -> f32 {
        self.mass
            .max(self.centre)
            .max(self.tensor)
            .max(self.reference)
    }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// The reference tensor in `f64`, by another decomposition than urto's: signed tetrahedra from
/// the box centre to each triangle, `∫x xᵀ = V/20 (Σ vᵢvᵢᵀ + s sᵀ)` (Tonon 2004).
fn tetrahedra_tensor(vertices: &[Vec3], triangles: &[[u32; 3]], density: f64) -> DMat3 {
    let o = urto::bounding::Aabb::from_points(vertices.iter().copied())
        .center()
        .as_dvec3();
    let (mut volume, mut first, mut second) = (0.0, DVec3::ZERO, DMat3::ZERO);
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize].as_dvec3() - o);
        let v = a.dot(b.cross(c)) / 6.0;
        let s = a + b + c;
        volume += v;
        first += s * (v / 4.0);
        second += (outer(a, a) + outer(b, b) + outer(c, c) + outer(s, s)) * (v / 20.0);
    }
    let com = first / volume;
    let central = (second - outer(com, com) * volume) * (density * volume.signum());
    let trace = central.x_axis.x + central.y_axis.y + central.z_axis.z;
    DMat3::from_diagonal(DVec3::splat(trace)) - central
}

/// parry's full tensor for a mesh, as `from_trimesh` sums it before diagonalising it.
fn parry_tensor(density: f32, vertices: &[Vec3], triangles: &[[u32; 3]]) -> Mat3 {
    use parry3d::mass_properties::details::*;
    let (volume, com) = trimesh_signed_volume_and_center_of_mass(vertices, triangles);
    let mut sum = Mat3::ZERO;
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        let v = parry3d::shape::Tetrahedron::new(com, a, b, c).signed_volume();
        sum += tetrahedron_unit_inertia_tensor_wrt_point(com, com, a, b, c) * v;
    }
    sum * (density * volume.signum())
}

fn parry_trimesh(density: f32, vertices: &[Vec3], triangles: &[[u32; 3]]) -> ParryMass {
    ParryMass::from_trimesh(density, vertices, triangles)
}

fn size_of(mesh: &TriMesh) -> f32 {
    mesh.local_aabb().extents().length()
}

/// An icosahedron subdivided `levels` times, projected on the sphere of `radius`.
fn icosphere(radius: f32, levels: u32) -> TriMesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut v: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .map(|(x, y, z)| Vec3::new(x, y, z).normalize())
    .to_vec();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut midpoint = |a: u32, b: u32, v: &mut Vec<Vec3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push(((v[a as usize] + v[b as usize]) * 0.5).normalize());
                v.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(4 * f.len());
        for [a, b, c] in f {
            let (ab, bc, ca) = (
                midpoint(a, b, &mut v),
                midpoint(b, c, &mut v),
                midpoint(c, a, &mut v),
            );
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    TriMesh::new(v.into_iter().map(|p| p * radius).collect(), f).unwrap()
}

/// The mesh rotated by `rotation` about its origin (f32, near the origin).
fn rotated(mesh: &TriMesh, rotation: Quat) -> Vec<Vec3> {
    mesh.vertices().iter().map(|v| rotation * *v).collect()
}

#[test]
fn spheres_boxes_capsules_and_half_spaces_match_parry_within_1e_6_relative() {
    let mut worst = Errors::default();
    for (r, density) in [(0.01, 7800.0), (0.5, 1000.0), (3.0, 1.0), (250.0, 0.1)] {
        let ours = Shape::sphere(r).mass_properties(density);
        let parry = parry3d::shape::Ball::new(r).mass_properties(density);
        worst = worst.worst(Errors::of_shape(&ours, &parry, r));
    }
    for (h, density) in [
        (Vec3::new(1.0, 2.0, 3.0), 1.0),
        (Vec3::new(0.01, 0.5, 4.0), 2700.0),
        (Vec3::splat(10.0), 0.5),
    ] {
        let ours = Shape::cuboid(h).mass_properties(density);
        let parry = parry3d::shape::Cuboid::new(h).mass_properties(density);
        worst = worst.worst(Errors::of_shape(&ours, &parry, h.length()));
    }
    for (half_length, r, density) in [(0.5, 0.25, 1000.0), (0.0, 1.0, 1.0), (3.0, 0.05, 7800.0)] {
        let ours = Shape::capsule(half_length, r).mass_properties(density);
        let parry = parry3d::shape::Capsule::new_z(half_length, r).mass_properties(density);
        worst = worst.worst(Errors::of_shape(&ours, &parry, half_length + r));
    }
    println!("spheres, boxes and capsules, worst relative errors: {worst:?}");
    assert!(worst.max().max(worst.moments) < 1e-6, "{worst:?}");
    let ground = Shape::half_space(Vec3::Z).mass_properties(1000.0);
    assert_eq!(ground, MassProperties::infinite());
    assert_eq!(ground.inverse_inertia(), Mat3::ZERO);
}

#[test]
fn closed_procedural_meshes_rotated_and_far_away_match_parry_within_1e_5_relative_and_its_eigenvalues_within_1e_4()
 {
    let meshes = [
        ("box", TriMesh::cuboid(Vec3::new(0.5, 1.0, 2.0)).unwrap()),
        ("uv sphere", TriMesh::uv_sphere(1.5, 24, 12).unwrap()),
        ("icosphere", icosphere(0.8, 3)),
        ("torus", TriMesh::torus(1.0, 0.3, 32, 16).unwrap()),
    ];
    let rotation = Quat::from_axis_angle(Vec3::new(0.3, -1.0, 0.6).normalize(), 1.1);
    let mut worst = Errors::default();
    for (name, mesh) in &meshes {
        for offset in [Vec3::ZERO, Vec3::new(1000.0, -600.0, 350.0)] {
            // The same f32 vertices for both: ours far away, parry's shifted back exactly
            // (x + o − o is exact for |x| ≪ |o|), its centre then moved by the offset.
            let near = rotated(mesh, rotation);
            let far: Vec<Vec3> = near.iter().map(|v| *v + offset).collect();
            let back: Vec<Vec3> = far.iter().map(|v| *v - offset).collect();
            let ours = MassProperties::trimesh(
                &TriMesh::new(far, mesh.triangles().to_vec()).unwrap(),
                500.0,
            );
            let mut parry = parry_trimesh(500.0, &back, mesh.triangles());
            parry.local_com += offset;
            let tensor = parry_tensor(500.0, &back, mesh.triangles());
            let reference = tetrahedra_tensor(&back, mesh.triangles(), 500.0);
            let e = Errors::of(&ours, &parry, tensor, size_of(mesh), Some(reference));
            println!("{name} at {offset}: {e:?}");
            worst = worst.worst(e);
        }
    }
    println!("procedural meshes, worst relative errors: {worst:?}");
    assert!(worst.max() < 1e-5 && worst.reference < 1e-6, "{worst:?}");
    assert!(worst.moments < 1e-4, "{worst:?}");
}

#[test]
fn pyvista_closed_meshes_match_parry_within_1e_5_relative() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let files = [
        "tests/data/ant.ply",
        "tests/data/nut.ply",
        "tests/data/sphere.ply",
        "examples/assets/ant.ply",
        "examples/assets/nut.ply",
    ];
    let mut worst = Errors::default();
    for file in files {
        let mesh = load_ply(root.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        for inward in [false, true] {
            let triangles: Vec<[u32; 3]> = if inward {
                mesh.triangles()
                    .iter()
                    .map(|t| [t[0], t[2], t[1]])
                    .collect()
            } else {
                mesh.triangles().to_vec()
            };
            let oriented = TriMesh::new(mesh.vertices().to_vec(), triangles.clone()).unwrap();
            let ours = MassProperties::trimesh(&oriented, 1000.0);
            let parry = parry_trimesh(1000.0, mesh.vertices(), &triangles);
            let tensor = parry_tensor(1000.0, mesh.vertices(), &triangles);
            let reference = tetrahedra_tensor(mesh.vertices(), &triangles, 1000.0);
            let e = Errors::of(&ours, &parry, tensor, size_of(&mesh), Some(reference));
            println!("{file} (inward: {inward}): mass {} {e:?}", ours.mass);
            assert!(ours.mass > 0.0 && ours.inverse_inertia().is_finite());
            worst = worst.worst(e);
        }
    }
    println!("PyVista meshes, worst relative errors: {worst:?}");
    assert!(
        worst.max().max(worst.moments) < 1e-5 && worst.reference < 1e-6,
        "{worst:?}"
    );
}

#[test]
fn the_open_airplane_is_a_thin_shell_with_a_finite_positive_tensor() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mesh = load_ply(root.join("tests/data/airplane.ply")).unwrap();
    let p = MassProperties::trimesh(&mesh, 1000.0);
    let thickness = MassProperties::SHELL_THICKNESS_FRACTION * size_of(&mesh);
    let expected = 1000.0 * mesh.area() * thickness;
    assert!((p.mass - expected).abs() < 1e-5 * expected, "{p:?}");
    assert!((p.local_center_of_mass - mesh.centroid()).length() < 1e-5 * size_of(&mesh));
    let (moments, _) = p.principal();
    assert!(
        moments.is_finite() && moments.min_element() > 0.0,
        "{moments}"
    );
    assert!(p.inverse_inertia().is_finite() && p.inverse_inertia() != Mat3::ZERO);
}

#[test]
fn uv_sphere_inertia_approaches_the_analytic_ball_within_1e_3_relative() {
    let (radius, density) = (2.0, 10.0);
    let ball = MassProperties::sphere(radius, density);
    let mut previous = f32::INFINITY;
    for (segments, rings) in [(8, 4), (16, 8), (32, 16), (64, 32), (128, 64), (256, 128)] {
        let mesh = TriMesh::uv_sphere(radius, segments, rings).unwrap();
        let p = MassProperties::trimesh(&mesh, density);
        let diff = (p.inertia - ball.inertia).abs().to_cols_array();
        let error = diff.into_iter().fold(0.0, f32::max) / ball.inertia.x_axis.x;
        println!("{segments}×{rings}: inertia relative error {error:.3e}");
        assert!(error < previous, "refining must get closer");
        assert!(p.local_center_of_mass.length() < 1e-5 * radius);
        previous = error;
    }
    assert!(previous < 1e-3, "{previous}");
}

#[test]
fn l_shaped_compound_matches_parry_sum_within_1e_5_relative() {
    let density = 800.0;
    let parts = [
        (Vec3::new(2.0, 0.25, 0.5), Vec3::ZERO, Quat::IDENTITY),
        (
            Vec3::new(0.25, 1.5, 0.5),
            Vec3::new(1.75, 1.75, 0.0),
            Quat::IDENTITY,
        ),
        (
            Vec3::new(0.3, 0.3, 0.3),
            Vec3::new(-1.0, 0.5, 1.0),
            Quat::from_rotation_z(0.7) * Quat::from_rotation_x(0.4),
        ),
    ];
    let ours = MassProperties::compound(parts.map(|(h, t, q)| {
        (
            Isometry::new(t, q),
            Shape::cuboid(h).mass_properties(density),
        )
    }));
    let parry = parts
        .map(|(h, t, q)| {
            parry3d::shape::Cuboid::new(h)
                .mass_properties(density)
                .transform_by(&Pose::from_parts(t, q))
        })
        .into_iter()
        .fold(ParryMass::default(), |a, b| a + b);
    let e = Errors::of_shape(&ours, &parry, 4.0);
    println!("L-shape: {e:?}");
    assert!(e.max().max(e.moments) < 1e-5, "{e:?}");
}

#[test]
fn meshes_are_solids_when_closed_and_thin_shells_when_open_or_flat_within_1e_6_relative() {
    let close = |a: f32, b: f32| (a - b).abs() <= 1e-6 * b.abs();
    let tensor_close = |a: Mat3, b: Mat3| relative(a.as_dmat3(), b.as_dmat3()) <= 1e-6;
    let h = Vec3::new(1.0, 0.5, 2.0);
    let (mesh, exact) = (TriMesh::cuboid(h).unwrap(), MassProperties::cuboid(h, 3.0));
    let flipped = mesh
        .triangles()
        .iter()
        .map(|t| [t[0], t[2], t[1]])
        .collect();
    let inward = TriMesh::new(mesh.vertices().to_vec(), flipped).unwrap();
    // One vertex per triangle corner, as STL gives: closed by position.
    let corners: Vec<Vec3> = mesh.iter_triangles().flat_map(|t| t.vertices()).collect();
    let soup = TriMesh::new(
        corners,
        (0..12).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
    );
    for m in [&mesh, &inward, &soup.unwrap()] {
        let solid = MassProperties::trimesh(m, 3.0);
        assert!(close(solid.mass, exact.mass), "{solid:?}");
        assert!(tensor_close(solid.inertia, exact.inertia), "{solid:?}");
    }
    // A unit square sheet, open: a shell of area 1 and thickness 1% of its diagonal √2.
    let sheet = TriMesh::grid_floor(1.0, 4).unwrap();
    let p = MassProperties::trimesh(&sheet, 100.0);
    let expected = 100.0 * MassProperties::SHELL_THICKNESS_FRACTION * 2f32.sqrt();
    assert!(close(p.mass, expected), "{p:?}");
    let i = p.mass / 12.0;
    assert!(tensor_close(
        p.inertia,
        Mat3::from_diagonal(Vec3::new(i, i, 2.0 * i))
    ));
    // The same sheet double-sided is closed but flat: a shell of twice the area.
    let mut both = sheet.triangles().to_vec();
    both.extend(sheet.triangles().iter().map(|t| [t[0], t[2], t[1]]));
    let double = TriMesh::new(sheet.vertices().to_vec(), both).unwrap();
    assert!(close(
        MassProperties::trimesh(&double, 100.0).mass,
        2.0 * expected
    ));
    // A box with one face missing is open: a shell, not 5/6 of a solid.
    let open = TriMesh::new(mesh.vertices().to_vec(), mesh.triangles()[2..].to_vec()).unwrap();
    let area = 2.0 * (1.0 * 4.0 + 2.0 * 4.0 + 2.0 * 1.0) - 1.0 * 4.0; // −x face gone
    let thickness = MassProperties::SHELL_THICKNESS_FRACTION * size_of(&mesh);
    let shell = MassProperties::trimesh(&open, 3.0);
    assert!(close(shell.mass, 3.0 * area * thickness), "{shell:?}");
    // A single triangle: never zero, never NaN.
    let tri = TriMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]).unwrap();
    let p = Shape::TriMesh(urto::geometry::MeshCollider::new(tri).unwrap()).mass_properties(1.0);
    assert!(p.mass > 0.0 && p.principal().0.min_element() > 0.0, "{p:?}");
    assert!(p.inverse_inertia().is_finite());
}

/// Relative difference, 0 when both are 0.
fn relative_scalar(ours: f32, theirs: f32) -> f32 {
    (ours - theirs).abs() / ours.abs().max(theirs.abs()).max(f32::MIN_POSITIVE)
}

/// Our shape along z against parry's along y: the same mass and, y and z swapped, the same
/// principal moments and centre of mass, within 1e-5 relative (the centre within 1e-6 of `size`).
fn assert_axial_matches_parry(ours: &MassProperties, parry: &ParryMass, size: f32, what: &str) {
    let (p, c) = (parry.principal_inertia(), parry.local_com);
    let i = &ours.inertia;
    let d = Vec3::new(i.x_axis.x, i.y_axis.y, i.z_axis.z);
    assert!(
        relative_scalar(ours.mass, parry.mass()) < 1e-5,
        "{what}: mass"
    );
    let com = ours.local_center_of_mass;
    let theirs = Vec3::new(c.x, c.z, c.y);
    assert!(
        (com - theirs).length() < 1e-6 * size,
        "{what}: {com} vs {c:?}"
    );
    for (a, b) in [(d.x, p.x), (d.y, p.z), (d.z, p.y)] {
        assert!(relative_scalar(a, b) < 1e-5, "{what}: {d} vs {p:?}");
    }
}

#[test]
fn cones_match_parry_within_1e_5_relative_their_centre_a_quarter_up_from_the_base() {
    for (h, r, density) in [(0.5, 0.25, 1000.0), (0.01, 1.0, 1.0), (3.0, 0.05, 7800.0)] {
        let ours = Shape::cone(h, r).mass_properties(density);
        // parry's cone runs along y (apex up), ours along z.
        let parry = parry3d::shape::Cone::new(h, r).mass_properties(density);
        assert_axial_matches_parry(&ours, &parry, h, &format!("cone {h} {r}"));
        let com = ours.local_center_of_mass;
        assert!((com.z + h / 2.0).abs() < 1e-6 * h, "{com}");
    }
}

#[test]
fn cylinders_and_convex_hulls_match_parry_within_1e_5_relative_and_hull_moments_within_1e_4() {
    for (h, r, density) in [(0.5, 0.25, 1000.0), (0.01, 1.0, 1.0), (3.0, 0.05, 7800.0)] {
        let ours = Shape::cylinder(h, r).mass_properties(density);
        // parry's cylinder runs along y, ours along z.
        let parry = parry3d::shape::Cylinder::new(h, r).mass_properties(density);
        assert_axial_matches_parry(&ours, &parry, h, &format!("cylinder {h} {r}"));
    }
    let mut points = Vec::new();
    for k in 0..40u32 {
        // A deterministic cloud: points on a twisted, squashed spiral.
        let t = k as f32 * 0.7;
        points.push(Vec3::new(
            t.cos() * 0.8,
            (1.3 * t).sin() * 0.5,
            (k as f32 / 20.0 - 1.0) * 0.6,
        ));
    }
    let hull = Shape::convex_hull(&points).unwrap();
    let ours = hull.mass_properties(500.0);
    // The reference: parry3d's own quickhull of the same points, integrated as a triangle
    // mesh. (parry's `ConvexPolyhedron::mass_properties` is 5.5e-4 off its own hull's volume
    // on this cloud: 640.83 kg where the divergence theorem over its triangles gives 641.18.)
    let cloud: Vec<_> = points
        .iter()
        .map(|v| parry3d::math::Vector::from_array(v.to_array()))
        .collect();
    let (hull_vertices, hull_triangles) = parry3d::transformation::convex_hull(&cloud);
    let hull_vertices: Vec<Vec3> = hull_vertices
        .iter()
        .map(|v| Vec3::from_array(v.to_array()))
        .collect();
    let parry = parry_trimesh(500.0, &hull_vertices, &hull_triangles);
    assert!(
        relative_scalar(ours.mass, parry.mass()) < 1e-5,
        "hull mass {} vs {}",
        ours.mass,
        parry.mass()
    );
    let com = Vec3::from_array(parry.local_com.to_array());
    assert!(ours.local_center_of_mass.distance(com) < 1e-5);
    let (moments, _) = ours.principal();
    let mut a = moments.to_array();
    let mut b = parry.principal_inertia().to_array();
    a.sort_by(f32::total_cmp);
    b.sort_by(f32::total_cmp);
    for (x, y) in a.iter().zip(&b) {
        assert!(
            relative_scalar(*x, *y) < 1e-4,
            "hull moments {a:?} vs {b:?}"
        );
    }
}

#[test]
fn an_ellipsoid_matches_a_finely_tessellated_one_within_1e_3_relative() {
    let radii = Vec3::new(0.5, 1.2, 0.3);
    let ours = Shape::ellipsoid(radii).mass_properties(1000.0);
    let sphere = TriMesh::uv_sphere(1.0, 256, 128).unwrap();
    let scaled: Vec<Vec3> = sphere.vertices().iter().map(|v| *v * radii).collect();
    let mesh = TriMesh::new(scaled, sphere.triangles().to_vec()).unwrap();
    let reference = MassProperties::trimesh(&mesh, 1000.0);
    assert!(
        relative_scalar(ours.mass, reference.mass) < 1e-3,
        "{} vs {}",
        ours.mass,
        reference.mass
    );
    for (a, b) in [
        (ours.inertia.x_axis.x, reference.inertia.x_axis.x),
        (ours.inertia.y_axis.y, reference.inertia.y_axis.y),
        (ours.inertia.z_axis.z, reference.inertia.z_axis.z),
    ] {
        assert!(relative_scalar(a, b) < 1e-3, "{a} vs {b}");
    }
}

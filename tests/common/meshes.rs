//! Test meshes: urto's procedural meshes, a random triangle soup, and the PLY files of
//! `tests/data/` loaded with urto's own loader.

use super::Mesh;
use super::rng::Rng;
use urto::geometry::TriMesh;
use urto::geometry::mesh_io::load_ply;

fn from_trimesh(mesh: TriMesh) -> Mesh {
    Mesh {
        vertices: mesh.vertices().to_vec(),
        triangles: mesh.triangles().to_vec(),
    }
}

/// A UV sphere: `stacks` bands of latitude, `slices` of longitude.
pub fn uv_sphere(radius: f32, stacks: u32, slices: u32) -> Mesh {
    from_trimesh(TriMesh::uv_sphere(radius, slices, stacks).expect("valid sphere parameters"))
}

/// A torus about z: tube radius `minor`, centre-line radius `major`, `nu × nv` quads.
pub fn torus(major: f32, minor: f32, nu: u32, nv: u32) -> Mesh {
    from_trimesh(TriMesh::torus(major, minor, nu, nv).expect("valid torus parameters"))
}

/// The BVH measurements' pair: two tori (radii 1 / 0.3 and 0.8 / 0.25) of about `n` triangles
/// each.
pub fn torus_pair(n: usize) -> (Mesh, Mesh) {
    let nv = ((n as f32 / 2.0 / 2.5).sqrt()).max(3.0) as u32;
    let nu = (n as u32 / 2 / nv).max(3);
    (torus(1.0, 0.3, nu, nv), torus(0.8, 0.25, nu, nv))
}

/// `n` independent random triangles of size up to `size` in a ball of radius `spread`.
pub fn soup(n: usize, spread: f32, size: f32, rng: &mut Rng) -> Mesh {
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for t in 0..n as u32 {
        let c = rng.in_ball(spread);
        for _ in 0..3 {
            vertices.push(c + rng.in_ball(size));
        }
        triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
    }
    Mesh {
        vertices,
        triangles,
    }
}

/// A PLY mesh from `tests/data/`.
pub fn ply(name: &str) -> Mesh {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    from_trimesh(load_ply(&path).expect("test mesh loads"))
}

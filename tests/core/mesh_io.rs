//! Loading meshes: the real PLY files of `tests/data` (from PyVista, see its README), OBJ and
//! STL files written here, and broken files of every kind, which must give errors, not panics.

use glam::Vec3;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use urto::geometry::mesh_io::{self, MeshLoadError, read_obj, read_ply, read_stl};
use urto::geometry::{MeshError, TriMesh};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// A fresh scratch directory for one test, removed by `Drop`.
struct TempDir(PathBuf);

impl TempDir {
    fn new(test: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("urto-mesh-io-{}-{test}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        Self(dir)
    }
    fn file(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let path = self.0.join(name);
        std::fs::write(&path, bytes).expect("write temp file");
        path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Undirected edges and how many triangles use each.
fn edge_uses(m: &TriMesh) -> BTreeMap<(u32, u32), usize> {
    let mut uses = BTreeMap::new();
    for t in m.triangles() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    uses
}

#[test]
fn the_pyvista_meshes_load_with_their_documented_counts() {
    // (file, vertices, triangles, closed) from tests/data/README.md.
    let expected = [
        ("ant.ply", 486, 912, true),
        ("nut.ply", 523, 1046, true),
        ("sphere.ply", 422, 840, true),
        ("airplane.ply", 1335, 2452, false),
    ];
    for (name, vertices, triangles, closed) in expected {
        let m = mesh_io::load(data(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.vertex_count(), vertices, "{name}");
        let dropped = m.report().degenerate_triangles_dropped;
        assert_eq!(m.triangle_count() + dropped, triangles, "{name}");
        println!(
            "{name}: {} triangles kept, {dropped} degenerate dropped",
            m.triangle_count()
        );
        let uses = edge_uses(&m);
        let every_edge_twice = uses.values().all(|&n| n == 2);
        if closed {
            assert!(dropped == 0 && every_edge_twice, "{name} should be closed");
        } else {
            assert!(!every_edge_twice, "{name} has open boundaries");
        }
        assert!(m.local_aabb().is_finite() && m.area() > 0.0);
    }
    let airplane = mesh_io::load_ply(data("airplane.ply")).unwrap();
    assert!(
        airplane.local_aabb().center().length() > 800.0,
        "large coordinates survive"
    );
}

#[test]
fn extensions_dispatch_in_any_case_and_unknown_ones_are_refused() {
    let dir = TempDir::new("dispatch");
    let bytes = std::fs::read(data("sphere.ply")).unwrap();
    let upper = dir.file("SPHERE.PLY", &bytes);
    assert_eq!(mesh_io::load(&upper).unwrap().triangle_count(), 840);
    let wrong = dir.file("sphere.mesh", &bytes);
    assert!(matches!(
        mesh_io::load(&wrong),
        Err(MeshLoadError::UnknownFormat(_))
    ));
    let none = dir.file("sphere", &bytes);
    assert!(matches!(
        mesh_io::load(&none),
        Err(MeshLoadError::UnknownFormat(_))
    ));
    let missing = mesh_io::load(dir.0.join("missing.obj"));
    assert!(
        matches!(missing, Err(MeshLoadError::Io { .. })),
        "{missing:?}"
    );
    let message = missing.unwrap_err().to_string();
    assert!(
        message.contains("missing.obj"),
        "the error names the file: {message}"
    );
}

const OBJ: &str = "\
# two objects: a textured quad and a triangle given with negative indices
mtllib does-not-exist.mtl
o quad
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
usemtl nothing
f 1/1/1 2/2/1 3/3/1 4/4/1
o triangle
v 0 0 1
v 1 0 1
v 0 1 1
f -3 -2 -1
l 1 2
";

#[test]
fn obj_files_load_triangulated_and_merged() {
    let dir = TempDir::new("obj");
    let m = mesh_io::load(dir.file("two.obj", OBJ.as_bytes())).unwrap();
    assert_eq!(m.triangle_count(), 3);
    let tris: Vec<[Vec3; 3]> = m.iter_triangles().map(|t| t.vertices()).collect();
    assert_eq!(tris[0], [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)]);
    assert_eq!(tris[1], [Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::Y]);
    assert_eq!(
        tris[2],
        [Vec3::Z, Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 1.0)]
    );
}

#[test]
fn broken_obj_files_are_errors() {
    type Check = fn(&Result<TriMesh, MeshLoadError>) -> bool;
    let cases: [(&str, Check); 6] = [
        ("v 0 0 0\nv 1 0 0\nf 1 2 x\n", |r| {
            matches!(r, Err(MeshLoadError::Parse { .. }))
        }),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", |r| {
            matches!(r, Err(MeshLoadError::Parse { .. }))
        }),
        ("v 0 0\nf 1 1 1\n", |r| {
            matches!(r, Err(MeshLoadError::Parse { .. }))
        }),
        ("v 0 0 0\nv 1 0 0\nv 2 0 0\n", |r| {
            matches!(r, Err(MeshLoadError::Unsupported { .. }))
        }),
        ("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", |r| {
            matches!(
                r,
                Err(MeshLoadError::Mesh(
                    MeshError::AllTrianglesDegenerate { .. }
                ))
            )
        }),
        ("v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", |r| {
            matches!(
                r,
                Err(MeshLoadError::Mesh(MeshError::NonFiniteVertex { .. }))
            )
        }),
    ];
    for (text, expected) in cases {
        let result = read_obj(text.as_bytes());
        assert!(expected(&result), "{text:?} gave {result:?}");
    }
    assert!(read_obj(&[0xff, 0xfe, 0x00]).is_err());
    // Texture indices far past usize are ignored with the texture data, not multiplied.
    let huge_vt = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/9223372036854775807 2/1 3/1\n";
    assert_eq!(read_obj(huge_vt.as_bytes()).unwrap().triangle_count(), 1);
}

fn to_stl(m: &TriMesh) -> Vec<stl_io::Triangle> {
    m.iter_triangles()
        .map(|t| stl_io::Triangle {
            normal: stl_io::Normal::new(t.normal().unwrap_or(Vec3::Z).to_array()),
            vertices: t.vertices().map(|v| stl_io::Vertex::new(v.to_array())),
        })
        .collect()
}

#[test]
fn stl_written_by_stl_io_reads_back_identically() {
    let dir = TempDir::new("stl");
    let original = TriMesh::torus(2.0, 0.5, 24, 12).unwrap();
    let mut bytes = Vec::new();
    stl_io::write_stl(&mut bytes, to_stl(&original).iter()).unwrap();
    let back = mesh_io::load(dir.file("torus.stl", &bytes)).unwrap();
    assert_eq!(back.triangle_count(), original.triangle_count());
    // Shared corners come back shared: same vertex count, same triangles.
    assert_eq!(back.vertex_count(), original.vertex_count());
    for (a, b) in original.iter_triangles().zip(back.iter_triangles()) {
        assert_eq!(a, b);
    }
    let ascii = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
        vertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
    assert_eq!(read_stl(ascii.as_bytes()).unwrap().triangle_count(), 1);
}

#[test]
fn truncated_and_empty_files_are_errors() {
    let ant = std::fs::read(data("ant.ply")).unwrap();
    for cut in [0, 10, 200, ant.len() / 2, ant.len() - 1] {
        let result = read_ply(&ant[..cut]);
        assert!(
            matches!(result, Err(MeshLoadError::Parse { .. })),
            "cut at {cut}: {result:?}"
        );
    }
    let airplane = std::fs::read(data("airplane.ply")).unwrap();
    assert!(read_ply(&airplane[..airplane.len() / 3]).is_err());
    let mut stl = Vec::new();
    stl_io::write_stl(
        &mut stl,
        to_stl(&TriMesh::cuboid(Vec3::ONE).unwrap()).iter(),
    )
    .unwrap();
    for cut in [0, 50, 84, stl.len() - 1] {
        assert!(read_stl(&stl[..cut]).is_err(), "STL cut at {cut}");
    }
    let mut no_triangles = stl[..80].to_vec();
    no_triangles.extend(0u32.to_le_bytes());
    assert!(matches!(
        read_stl(&no_triangles),
        Err(MeshLoadError::Unsupported { .. })
    ));
    assert!(read_obj(b"").is_err());
}

/// A tiny deterministic mutation fuzzer: flipped bytes, overwritten digits and truncations of
/// every format must give a result, never a panic or an abort.
#[test]
fn mutated_files_never_panic() {
    let mut stl = Vec::new();
    stl_io::write_stl(
        &mut stl,
        to_stl(&TriMesh::cuboid(Vec3::ONE).unwrap()).iter(),
    )
    .unwrap();
    let mut obj_of_sphere = String::new();
    let sphere = TriMesh::uv_sphere(1.0, 8, 6).unwrap();
    for v in sphere.vertices() {
        obj_of_sphere += &format!("v {} {} {}\n", v.x, v.y, v.z);
    }
    for t in sphere.triangles() {
        obj_of_sphere += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    type Reader = fn(&[u8]) -> Result<TriMesh, MeshLoadError>;
    let inputs: [(Vec<u8>, Reader); 4] = [
        (std::fs::read(data("sphere.ply")).unwrap(), read_ply),
        (std::fs::read(data("airplane.ply")).unwrap(), read_ply),
        (stl, read_stl),
        (obj_of_sphere.into_bytes(), read_obj),
    ];
    let mut seed = 0x0dd_ba11_u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let (mut ok, mut err) = (0, 0);
    for (bytes, read) in &inputs {
        for _ in 0..300 {
            let mut m = bytes.clone();
            for _ in 0..1 + next() % 4 {
                let at = (next() as usize) % m.len();
                m[at] = match next() % 3 {
                    0 => next() as u8,
                    1 => b"0123456789-"[(next() % 11) as usize],
                    _ => 0xff,
                };
            }
            if next() % 4 == 0 {
                m.truncate((next() as usize) % m.len());
            }
            match read(&m) {
                Ok(_) => ok += 1,
                Err(_) => err += 1,
            }
        }
    }
    println!("mutations: {ok} still load, {err} refused");
    assert!(err > 0);
}

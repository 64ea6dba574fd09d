//! Procedural triangle meshes for tests, benches and examples: a UV sphere, a box, a torus and a
//! height-field floor.
//!
//! All are built with z up (the slides' vertical), centred on the origin, with triangles
//! counter-clockwise seen from outside (closed meshes) or from above (floors). Closed meshes are
//! watertight: every edge is shared by exactly two triangles running it in opposite directions.
//! Bad parameters give [`MeshError::InvalidParameter`]; sizes are capped at
//! [`MAX_PROCEDURAL_VERTICES`] so that a typo cannot ask for gigabytes.

use crate::geometry::{MeshError, TriMesh};
use glam::Vec3;
use std::f32::consts::{PI, TAU};

/// Largest vertex count a procedural mesh may have (16 Mi).
pub const MAX_PROCEDURAL_VERTICES: u64 = 1 << 24;

fn invalid(why: String) -> MeshError {
    MeshError::InvalidParameter(why)
}

fn positive(name: &str, value: f32) -> Result<(), MeshError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(format!(
            "{name} must be finite and > 0, got {value}"
        )))
    }
}

fn at_least(name: &str, value: u32, min: u32) -> Result<(), MeshError> {
    if value >= min {
        Ok(())
    } else {
        Err(invalid(format!("{name} must be >= {min}, got {value}")))
    }
}

fn capped(vertex_count: u64) -> Result<(), MeshError> {
    if vertex_count <= MAX_PROCEDURAL_VERTICES {
        Ok(())
    } else {
        Err(invalid(format!(
            "{vertex_count} vertices requested, more than {MAX_PROCEDURAL_VERTICES}"
        )))
    }
}

/// Splits the quad `a, b, c, d` (counter-clockwise) into two triangles along `a–c`.
fn quad(triangles: &mut Vec<[u32; 3]>, a: u32, b: u32, c: u32, d: u32) {
    triangles.push([a, b, c]);
    triangles.push([a, c, d]);
}

impl TriMesh {
    /// A sphere of `radius` with `segments` meridians (≥ 3) and `rings` bands from pole to pole
    /// (≥ 2): one vertex per pole and `rings - 1` circles of `segments` vertices, all exactly
    /// on the sphere (so the mesh lies inside it).
    pub fn uv_sphere(radius: f32, segments: u32, rings: u32) -> Result<TriMesh, MeshError> {
        positive("radius", radius)?;
        at_least("segments", segments, 3)?;
        at_least("rings", rings, 2)?;
        capped(2 + segments as u64 * (rings as u64 - 1))?;
        let mut vertices = vec![Vec3::Z * radius];
        for ring in 1..rings {
            let (sin_t, cos_t) = (PI * ring as f32 / rings as f32).sin_cos();
            for s in 0..segments {
                let (sin_p, cos_p) = (TAU * s as f32 / segments as f32).sin_cos();
                vertices.push(Vec3::new(sin_t * cos_p, sin_t * sin_p, cos_t) * radius);
            }
        }
        let south = vertices.len() as u32;
        vertices.push(-Vec3::Z * radius);
        let at = |ring: u32, s: u32| 1 + (ring - 1) * segments + s % segments;
        let mut triangles = Vec::with_capacity(2 * (segments * (rings - 1)) as usize);
        for s in 0..segments {
            triangles.push([0, at(1, s), at(1, s + 1)]);
            for ring in 1..rings - 1 {
                let (a, b) = (at(ring, s), at(ring, s + 1));
                let (c, d) = (at(ring + 1, s + 1), at(ring + 1, s));
                quad(&mut triangles, a, d, c, b);
            }
            triangles.push([south, at(rings - 1, s + 1), at(rings - 1, s)]);
        }
        TriMesh::new(vertices, triangles)
    }

    /// The box `[-h, h]`: 8 corners, 12 triangles.
    pub fn cuboid(half_extents: Vec3) -> Result<TriMesh, MeshError> {
        for (name, value) in ["half_extents.x", "half_extents.y", "half_extents.z"]
            .into_iter()
            .zip(half_extents.to_array())
        {
            positive(name, value)?;
        }
        // Corner k has coordinate i at +h when bit i of k is set.
        let vertices = (0..8)
            .map(|k: u32| {
                let sign = |bit: u32| if k & (1 << bit) != 0 { 1.0 } else { -1.0 };
                half_extents * Vec3::new(sign(0), sign(1), sign(2))
            })
            .collect();
        // Each face counter-clockwise seen from outside: -x, +x, -y, +y, -z, +z.
        let faces = [
            [0, 4, 6, 2],
            [1, 3, 7, 5],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 2, 3, 1],
            [4, 5, 7, 6],
        ];
        let mut triangles = Vec::with_capacity(12);
        for [a, b, c, d] in faces {
            quad(&mut triangles, a, b, c, d);
        }
        TriMesh::new(vertices, triangles)
    }

    /// A ring torus around the z axis: tube centre at `major_radius`, tube radius
    /// `minor_radius` (`0 < minor < major`, so the surface does not cross itself), with
    /// `major_segments` (≥ 3) steps around z and `minor_segments` (≥ 3) around the tube.
    pub fn torus(
        major_radius: f32,
        minor_radius: f32,
        major_segments: u32,
        minor_segments: u32,
    ) -> Result<TriMesh, MeshError> {
        positive("major_radius", major_radius)?;
        positive("minor_radius", minor_radius)?;
        if minor_radius >= major_radius {
            return Err(invalid(format!(
                "minor_radius ({minor_radius}) must be smaller than major_radius ({major_radius})"
            )));
        }
        at_least("major_segments", major_segments, 3)?;
        at_least("minor_segments", minor_segments, 3)?;
        capped(major_segments as u64 * minor_segments as u64)?;
        let mut vertices = Vec::with_capacity((major_segments * minor_segments) as usize);
        for i in 0..major_segments {
            let (sin_u, cos_u) = (TAU * i as f32 / major_segments as f32).sin_cos();
            for j in 0..minor_segments {
                let (sin_v, cos_v) = (TAU * j as f32 / minor_segments as f32).sin_cos();
                let rho = major_radius + minor_radius * cos_v;
                vertices.push(Vec3::new(rho * cos_u, rho * sin_u, minor_radius * sin_v));
            }
        }
        let at = |i: u32, j: u32| (i % major_segments) * minor_segments + j % minor_segments;
        let mut triangles = Vec::with_capacity(2 * vertices.len());
        for i in 0..major_segments {
            for j in 0..minor_segments {
                quad(
                    &mut triangles,
                    at(i, j),
                    at(i + 1, j),
                    at(i + 1, j + 1),
                    at(i, j + 1),
                );
            }
        }
        TriMesh::new(vertices, triangles)
    }

    /// A flat square floor at z = 0, `size` wide, centred on the origin, split into
    /// `cells × cells` squares (two triangles each), facing +z.
    pub fn grid_floor(size: f32, cells: u32) -> Result<TriMesh, MeshError> {
        Self::height_field(size, cells, |_, _| 0.0)
    }

    /// A bumpy floor: the grid of [`grid_floor`](Self::grid_floor) with each vertex `(x, y)`
    /// lifted to `z = height(x, y)`. A non-finite height is refused by validation.
    pub fn height_field(
        size: f32,
        cells: u32,
        height: impl Fn(f32, f32) -> f32,
    ) -> Result<TriMesh, MeshError> {
        positive("size", size)?;
        at_least("cells", cells, 1)?;
        let side = cells as u64 + 1;
        capped(side.saturating_mul(side))?;
        let step = size / cells as f32;
        let coordinate = |i: u32| -0.5 * size + step * i as f32;
        let mut vertices = Vec::with_capacity((side * side) as usize);
        for row in 0..=cells {
            for column in 0..=cells {
                let (x, y) = (coordinate(column), coordinate(row));
                vertices.push(Vec3::new(x, y, height(x, y)));
            }
        }
        let at = |column: u32, row: u32| row * (cells + 1) + column;
        let mut triangles = Vec::with_capacity(2 * (cells * cells) as usize);
        for row in 0..cells {
            for column in 0..cells {
                let (a, b) = (at(column, row), at(column + 1, row));
                let (c, d) = (at(column + 1, row + 1), at(column, row + 1));
                quad(&mut triangles, a, b, c, d);
            }
        }
        TriMesh::new(vertices, triangles)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    /// Checks watertightness and consistent orientation: every directed edge appears once and
    /// its reverse appears once. Returns `V - E + F`.
    fn closed_euler_characteristic(m: &TriMesh) -> i64 {
        let mut directed = BTreeMap::new();
        for t in m.triangles() {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &n) in &directed {
            assert_eq!(n, 1, "edge {a}->{b} used {n} times");
            assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}->{b} has no twin");
        }
        let edges = directed.len() as i64 / 2;
        m.vertex_count() as i64 - edges + m.triangle_count() as i64
    }

    /// Divergence theorem: positive for a closed mesh with outward triangles.
    fn signed_volume(m: &TriMesh) -> f64 {
        m.iter_triangles()
            .map(|t| {
                let [a, b, c] = t.vertices().map(Vec3::as_dvec3);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn sphere_is_closed_outward_and_converges_to_the_ball() {
        let m = TriMesh::uv_sphere(2.0, 32, 16).unwrap();
        assert_eq!(m.vertex_count(), 2 + 32 * 15);
        assert_eq!(m.triangle_count(), 2 * 32 * 15);
        assert_eq!(closed_euler_characteristic(&m), 2);
        assert!(m.vertices().iter().all(|v| (v.length() - 2.0).abs() < 1e-5));
        let exact = 4.0 / 3.0 * std::f64::consts::PI * 8.0;
        let v = signed_volume(&m);
        assert!(v > 0.95 * exact && v < exact, "{v} vs {exact}");
        let finer = signed_volume(&TriMesh::uv_sphere(2.0, 64, 32).unwrap());
        assert!(finer > v && finer < exact);
        assert_eq!(m.report().degenerate_triangles_dropped, 0);
    }

    #[test]
    fn cuboid_is_closed_with_the_exact_volume() {
        let m = TriMesh::cuboid(Vec3::new(0.5, 1.0, 2.0)).unwrap();
        assert_eq!((m.vertex_count(), m.triangle_count()), (8, 12));
        assert_eq!(closed_euler_characteristic(&m), 2);
        assert!((signed_volume(&m) - 8.0).abs() < 1e-9);
        assert!((m.area() - 2.0 * (2.0 + 4.0 + 8.0)).abs() < 1e-5);
    }

    #[test]
    fn torus_is_closed_with_genus_one() {
        let m = TriMesh::torus(2.0, 0.5, 48, 24).unwrap();
        assert_eq!(closed_euler_characteristic(&m), 0);
        let exact = 2.0 * std::f64::consts::PI.powi(2) * 2.0 * 0.25;
        let v = signed_volume(&m);
        assert!((v - exact).abs() < 0.02 * exact, "{v} vs {exact}");
    }

    #[test]
    fn floors_face_up_and_follow_the_height() {
        let flat = TriMesh::grid_floor(10.0, 4).unwrap();
        assert_eq!(flat.triangle_count(), 32);
        assert!((flat.area() - 100.0).abs() < 1e-4);
        assert!(flat.iter_triangles().all(|t| t.normal() == Some(Vec3::Z)));
        let bump = |x: f32, y: f32| 0.3 * (x * 0.7).sin() * (y * 0.5).cos();
        let bumpy = TriMesh::height_field(10.0, 8, bump).unwrap();
        assert!(bumpy.vertices().iter().all(|v| v.z == bump(v.x, v.y)));
        assert!(
            bumpy
                .iter_triangles()
                .all(|t| t.normal().is_some_and(|n| n.z > 0.5))
        );
        assert_eq!(bumpy.local_aabb().min.x, -5.0);
        assert_eq!(bumpy.local_aabb().max.y, 5.0);
    }

    #[test]
    fn bad_parameters_are_errors() {
        assert!(TriMesh::uv_sphere(0.0, 8, 8).is_err());
        assert!(TriMesh::uv_sphere(1.0, 2, 8).is_err());
        assert!(TriMesh::uv_sphere(1.0, 8, 1).is_err());
        assert!(TriMesh::uv_sphere(f32::NAN, 8, 8).is_err());
        assert!(TriMesh::uv_sphere(1.0, u32::MAX, u32::MAX).is_err());
        assert!(TriMesh::cuboid(Vec3::new(1.0, 0.0, 1.0)).is_err());
        assert!(TriMesh::torus(1.0, 1.0, 8, 8).is_err());
        assert!(TriMesh::torus(1.0, 0.5, 8, 2).is_err());
        assert!(TriMesh::grid_floor(-1.0, 4).is_err());
        assert!(TriMesh::grid_floor(1.0, 0).is_err());
        assert!(TriMesh::grid_floor(1.0, u32::MAX).is_err());
        let nan = TriMesh::height_field(1.0, 2, |_, _| f32::NAN);
        assert!(matches!(nan, Err(MeshError::NonFiniteVertex { .. })));
    }
}

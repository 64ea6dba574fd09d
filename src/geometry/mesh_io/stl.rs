//! STL (ASCII or binary) through `stl_io`.

use super::MeshLoadError;
use crate::geometry::TriMesh;
use glam::Vec3;
use std::io::Cursor;

const FORMAT: &str = "STL";

/// Reads an STL file, ASCII or binary (told apart by `stl_io`).
///
/// STL stores each triangle's corners separately; `stl_io` shares corners with identical
/// coordinates (numbered in order of first appearance, so the result is deterministic). The
/// stored facet normals are ignored. Use [`TriMesh::weld`] to merge nearly equal corners.
pub fn read_stl(bytes: &[u8]) -> Result<TriMesh, MeshLoadError> {
    let indexed = stl_io::read_stl(&mut Cursor::new(bytes)).map_err(|e| MeshLoadError::Parse {
        format: FORMAT,
        message: e.to_string(),
    })?;
    if indexed.faces.is_empty() {
        return Err(MeshLoadError::Unsupported {
            format: FORMAT,
            message: "no triangles".into(),
        });
    }
    let vertices = indexed.vertices.iter().map(|v| Vec3::from(v.0)).collect();
    let triangles = indexed
        .faces
        .iter()
        .map(|f| {
            let index = |i: usize| {
                u32::try_from(i).map_err(|_| MeshLoadError::Unsupported {
                    format: FORMAT,
                    message: "more vertices than u32 indexes".into(),
                })
            };
            Ok([
                index(f.vertices[0])?,
                index(f.vertices[1])?,
                index(f.vertices[2])?,
            ])
        })
        .collect::<Result<Vec<_>, MeshLoadError>>()?;
    Ok(TriMesh::new(vertices, triangles)?)
}

//! Wavefront OBJ through `tobj`.

use super::MeshLoadError;
use crate::geometry::TriMesh;
use glam::Vec3;

const FORMAT: &str = "OBJ";

/// Reads an OBJ file's positions (`v`) and faces (`f`, polygons split into fans by `tobj`),
/// merging all objects and groups into one mesh.
///
/// Only `v`, `f`, `o` and `g` lines reach the parser. Texture and normal data are dropped
/// first, so their indices — which `tobj` multiplies without overflow checks — cannot make a
/// corrupt file panic, and material libraries are never opened. Points and lines are ignored.
pub fn read_obj(bytes: &[u8]) -> Result<TriMesh, MeshLoadError> {
    let text = std::str::from_utf8(bytes).map_err(|e| MeshLoadError::Parse {
        format: FORMAT,
        message: format!("not UTF-8 text: {e}"),
    })?;
    let geometry: String = text
        .lines()
        .filter(|line| matches!(line.split_whitespace().next(), Some("v" | "f" | "o" | "g")))
        .flat_map(|line| [line, "\n"])
        .collect();
    // Single index, triangulated, points and lines ignored (and whatever fields tobj features
    // add, at their neutral values).
    let options = tobj::GPU_LOAD_OPTIONS;
    let (models, _no_materials) = tobj::load_obj_buf(&mut geometry.as_bytes(), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| MeshLoadError::Parse {
        format: FORMAT,
        message: e.to_string(),
    })?;
    let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
    for model in &models {
        let base = u32::try_from(vertices.len()).map_err(|_| too_many())?;
        let mesh = &model.mesh;
        vertices.extend(mesh.positions.chunks_exact(3).map(Vec3::from_slice));
        for t in mesh.indices.chunks_exact(3) {
            let shift = |i: u32| i.checked_add(base).ok_or_else(too_many);
            triangles.push([shift(t[0])?, shift(t[1])?, shift(t[2])?]);
        }
    }
    if triangles.is_empty() {
        return Err(MeshLoadError::Unsupported {
            format: FORMAT,
            message: "no faces".into(),
        });
    }
    Ok(TriMesh::new(vertices, triangles)?)
}

fn too_many() -> MeshLoadError {
    MeshLoadError::Unsupported {
        format: FORMAT,
        message: "more vertices than u32 indexes".into(),
    }
}

//! Loading triangle meshes from files: Wavefront OBJ (`tobj`), STL (`stl_io`, ASCII or
//! binary) and PLY (`ply-rs-bw`, ASCII or binary), each parsed by a maintained crate and then
//! validated into a [triangle mesh](crate::geometry::TriMesh).
//!
//! Only geometry is read: positions and faces. Polygons are split into triangle fans (OBJ, PLY);
//! normals, texture coordinates, colours and materials are ignored (collision needs none of
//! them). Every failure is an error, never a panic: a missing file, text that does not parse, a
//! file without faces, and corrupt counts (see the PLY notes) all come back as a
//! [`MeshLoadError`].

#[cfg(feature = "mesh-io")]
mod obj;
#[cfg(feature = "mesh-io")]
mod ply;
#[cfg(feature = "mesh-io")]
mod stl;

#[cfg(feature = "mesh-io")]
pub use obj::read_obj;
#[cfg(feature = "mesh-io")]
pub use ply::read_ply;
#[cfg(feature = "mesh-io")]
pub use stl::read_stl;

use crate::geometry::MeshError;
#[cfg(feature = "mesh-io")]
use crate::geometry::TriMesh;
use std::fmt;
#[cfg(feature = "mesh-io")]
use std::path::Path;
use std::path::PathBuf;

/// Why a mesh file could not be loaded.
#[derive(Debug)]
pub enum MeshLoadError {
    /// The file could not be read (missing, unreadable…).
    Io {
        /// The file asked for.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// The extension is not one of `obj`, `stl`, `ply` (any case).
    UnknownFormat(PathBuf),
    /// The content is not valid for its format (syntax, truncation, corrupt counts).
    Parse {
        /// `"OBJ"`, `"STL"` or `"PLY"`.
        format: &'static str,
        /// The parser's explanation.
        message: String,
    },
    /// Valid in its format, but not something urto can collide (no faces, no positions…).
    Unsupported {
        /// `"OBJ"`, `"STL"` or `"PLY"`.
        format: &'static str,
        /// What is missing or unusable.
        message: String,
    },
    /// Parsed, but the geometry does not make a valid mesh (see [`MeshError`]).
    Mesh(MeshError),
}

impl fmt::Display for MeshLoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io { path, source } => write!(f, "cannot read {}: {source}", path.display()),
            Self::UnknownFormat(path) => write!(
                f,
                "unknown mesh format for {} (expected .obj, .stl or .ply)",
                path.display()
            ),
            Self::Parse { format, message } => write!(f, "invalid {format} file: {message}"),
            Self::Unsupported { format, message } => {
                write!(f, "unsupported {format} content: {message}")
            }
            Self::Mesh(e) => write!(f, "invalid mesh: {e}"),
        }
    }
}

impl std::error::Error for MeshLoadError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io { source, .. } => Some(source),
            Self::Mesh(e) => Some(e),
            _ => None,
        }
    }
}

impl From<MeshError> for MeshLoadError {
    fn from(e: MeshError) -> Self {
        Self::Mesh(e)
    }
}

#[cfg(feature = "mesh-io")]
/// Loads a mesh, choosing the format by the file extension (`.obj`, `.stl`, `.ply`, any case).
pub fn load(path: impl AsRef<Path>) -> Result<TriMesh, MeshLoadError> {
    let path = path.as_ref();
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("obj") => load_obj(path),
        Some("stl") => load_stl(path),
        Some("ply") => load_ply(path),
        _ => Err(MeshLoadError::UnknownFormat(path.to_path_buf())),
    }
}

#[cfg(feature = "mesh-io")]
/// Loads a Wavefront OBJ file (see [`read_obj`]).
pub fn load_obj(path: impl AsRef<Path>) -> Result<TriMesh, MeshLoadError> {
    read_obj(&read_file(path.as_ref())?)
}

#[cfg(feature = "mesh-io")]
/// Loads an STL file, ASCII or binary (see [`read_stl`]).
pub fn load_stl(path: impl AsRef<Path>) -> Result<TriMesh, MeshLoadError> {
    read_stl(&read_file(path.as_ref())?)
}

#[cfg(feature = "mesh-io")]
/// Loads a PLY file, ASCII or binary (see [`read_ply`]).
pub fn load_ply(path: impl AsRef<Path>) -> Result<TriMesh, MeshLoadError> {
    read_ply(&read_file(path.as_ref())?)
}

#[cfg(feature = "mesh-io")]
fn read_file(path: &Path) -> Result<Vec<u8>, MeshLoadError> {
    std::fs::read(path).map_err(|source| MeshLoadError::Io {
        path: path.to_path_buf(),
        source,
    })
}

//! Why a hierarchy cannot be built or refitted.

use std::fmt;

/// Bad input to [`Bvh::build`](super::Bvh::build) or [`Bvh::refit`](super::Bvh::refit).
#[derive(Clone, Debug, PartialEq)]
pub enum BvhError {
    /// No triangles: a hierarchy needs at least one.
    EmptyMesh,
    /// More triangles than a hierarchy's `u32` node indices can cover (2³¹ − 1).
    TooManyTriangles(usize),
    /// A vertex with a NaN or infinite coordinate.
    NonFiniteVertex {
        /// Its index in the vertex array.
        vertex: usize,
    },
    /// A triangle naming a vertex past the end of the vertex array.
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The offending vertex index.
        index: u32,
        /// Length of the vertex array.
        vertex_count: usize,
    },
    /// `leaf_size` must be at least 1.
    BadLeafSize(usize),
    /// The SAH bin count must lie in `2..=MAX_SAH_BINS`.
    BadBinCount(usize),
    /// Refitting with a different number of triangles than the hierarchy was built over.
    TriangleCountChanged {
        /// Triangles in the hierarchy.
        built: usize,
        /// Triangles given now.
        given: usize,
    },
}

impl fmt::Display for BvhError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::EmptyMesh => write!(f, "cannot build a hierarchy over a mesh without triangles"),
            Self::TooManyTriangles(n) => {
                write!(f, "{n} triangles: a hierarchy indexes at most 2^31 - 1")
            }
            Self::NonFiniteVertex { vertex } => {
                write!(f, "vertex {vertex} has a NaN or infinite coordinate")
            }
            Self::IndexOutOfRange {
                triangle,
                index,
                vertex_count,
            } => write!(
                f,
                "triangle {triangle} names vertex {index}, but there are only {vertex_count}"
            ),
            Self::BadLeafSize(n) => write!(f, "leaf size must be at least 1, got {n}"),
            Self::BadBinCount(n) => {
                write!(
                    f,
                    "SAH bin count must be in 2..={}, got {n}",
                    super::MAX_SAH_BINS
                )
            }
            Self::TriangleCountChanged { built, given } => write!(
                f,
                "hierarchy was built over {built} triangles, refit was given {given}"
            ),
        }
    }
}

impl std::error::Error for BvhError {}

//! Bottom-up update of a hierarchy's BVs after its vertices move (deformation, animation),
//! keeping the tree's topology.
//!
//! Leaves are refitted to their triangles; inner nodes merge their two children's BVs
//! ([`Bv::merged`]). Children always follow their parent in the node array, so one reverse sweep
//! sees every child before its parent. A merged BV is looser than one fitted to the node's
//! triangles — markedly for OBBs, whose merge refits the 16 corners of the two children — so a
//! mesh that deforms a lot is better rebuilt.

use super::build::validate_mesh;
use super::{Bvh, BvhError};
use crate::bounding::{Bv, TriangleSet};
use glam::Vec3;

impl<B: Bv> Bvh<B> {
    /// Refits every BV to the moved mesh; same triangles (count and indexing) as at build time.
    pub fn refit(&mut self, vertices: &[Vec3], triangles: &[[u32; 3]]) -> Result<(), BvhError> {
        validate_mesh(vertices, triangles)?;
        if triangles.len() != self.order.len() {
            return Err(BvhError::TriangleCountChanged {
                built: self.order.len(),
                given: triangles.len(),
            });
        }
        let mut corners = Vec::new();
        for i in (0..self.nodes.len()).rev() {
            let node = self.nodes[i];
            let bv = match (node.children(), node.triangle_range()) {
                (Some([l, r]), _) => self.nodes[l as usize].bv.merged(&self.nodes[r as usize].bv),
                (None, Some(range)) => {
                    corners.clear();
                    corners.extend(
                        self.order[range]
                            .iter()
                            .map(|&t| triangles[t as usize].map(|v| vertices[v as usize])),
                    );
                    B::fit_triangles(&TriangleSet::new(&corners))
                }
                // A node is a leaf or has children.
                (None, None) => continue,
            };
            self.nodes[i].bv = bv;
            self.nodes[i].size = bv.size();
        }
        Ok(())
    }
}

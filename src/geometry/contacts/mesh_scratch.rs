//! The reusable buffers of the mesh contact tests, and the work they count.
//!
//! A mesh query visits a hierarchy (a node stack or pair queue), collects candidate contact
//! points from many triangles, and lists the triangles that touched. Keeping those buffers in a
//! [`ContactScratch`] owned by the caller (the narrow phase keeps one in a resource) means a warm
//! query allocates nothing: buffers are cleared, never dropped. The scratch also sums the
//! hierarchy's cost counters (`Nv`, `Nn`, `Ns` of the slides' `Tc = Nv*Cv + Nn*Cn + Ns*Cs`) over
//! the queries it served, so a caller can report the work of a whole step.

use super::mesh_manifold::Contribution;
use crate::bounding::Obb;
use crate::bvh::{QueryScratch, QueryStats};
use crate::geometry::{ContactManifold, ContactPoint, MeshCollider, Triangle};
use glam::Vec3;
use std::ops::ControlFlow;

/// Stands for "no triangle" in [`ContactScratch::hits`], on the side of a primitive shape.
pub const NO_TRIANGLE: u32 = u32::MAX;

/// Buffers and counters for [`contact_with_scratch`](super::contact_with_scratch); create once,
/// pass to every query.
#[derive(Debug, Default)]
pub struct ContactScratch {
    pub(crate) query: QueryScratch,
    /// Triangle pairs of the last query, in the caller's (A, B) order.
    pub(crate) hits: Vec<[u32; 2]>,
    /// The triangle contacts, before merging.
    pub(crate) contributions: Vec<Contribution>,
    /// Their candidate contact points.
    pub(crate) points: Vec<ContactPoint>,
    /// The points of the contributions kept by the merge.
    pub(crate) kept: Vec<ContactPoint>,
    /// Vertex indices (the mesh–half-space test collects each vertex once).
    pub(crate) vertices: Vec<u32>,
    record_hits: bool,
    stats: QueryStats,
}

impl ContactScratch {
    /// Empty buffers (they grow on first use and are kept), hit recording off.
    pub fn new() -> Self {
        Self::default()
    }

    /// Turns on or off the recording of the triangles that touched in mesh–primitive queries
    /// (mesh–mesh queries always list their intersecting pairs: they need them). Off by default,
    /// so that only debugging pays for it.
    pub fn set_record_hits(&mut self, on: bool) {
        self.record_hits = on;
    }

    /// True when mesh–primitive queries record their triangles.
    pub fn records_hits(&self) -> bool {
        self.record_hits
    }

    /// The triangles that produced contacts in the last query, as pairs `[triangle of A,
    /// triangle of B]` in the order the query was asked, with [`NO_TRIANGLE`] for a primitive
    /// side. Mesh–mesh: every intersecting triangle pair (in traversal order). Mesh–primitive:
    /// each triangle in contact, only while [`set_record_hits`](Self::set_record_hits) is on.
    /// Empty after a query between primitives.
    pub fn hits(&self) -> &[[u32; 2]] {
        &self.hits
    }

    /// The hierarchy work summed over the queries since the last [`take_stats`](Self::take_stats).
    pub fn stats(&self) -> QueryStats {
        self.stats
    }

    /// Returns the summed work and starts a new sum.
    pub fn take_stats(&mut self) -> QueryStats {
        std::mem::take(&mut self.stats)
    }

    /// Adds one query's work.
    pub(crate) fn count(&mut self, stats: QueryStats) {
        self.stats += stats;
    }

    /// Clears the per-query buffers.
    pub(crate) fn begin_query(&mut self) {
        self.hits.clear();
        self.contributions.clear();
        self.points.clear();
        self.vertices.clear();
    }

    /// Merges the contributions into one manifold carried to the world by `pose` (see
    /// `mesh_manifold.rs`).
    pub(crate) fn merge(
        &mut self,
        pose: &crate::geometry::Isometry,
    ) -> Option<crate::geometry::ContactManifold> {
        super::mesh_manifold::merge_contributions(
            &self.contributions,
            &self.points,
            &mut self.kept,
            pose,
        )
    }

    /// Replaces the last query's hits (an answer that came from a cache brings its own).
    #[cfg(feature = "ecs")]
    pub(crate) fn set_hits(&mut self, hits: &[[u32; 2]]) {
        self.hits.clear();
        self.hits.extend_from_slice(hits);
    }

    /// Swaps the sides of the recorded hits (the dispatch ran the pair in the other order).
    pub(crate) fn flip_hits(&mut self) {
        for h in &mut self.hits {
            h.swap(0, 1);
        }
    }

    /// The leaf work of every mesh–primitive test, as a new query: descends `mesh`'s hierarchy
    /// through the nodes `node` keeps, collects the contact `test` finds for each triangle of
    /// the leaves reached (with the triangle's index, which its points' feature ids take in),
    /// records the triangles when asked to, and counts the work. The caller merges.
    pub(crate) fn collect_triangle_contacts<C: TriangleContact>(
        &mut self,
        mesh: &MeshCollider,
        node: impl FnMut(&Obb) -> bool,
        mut test: impl FnMut(u32, &Triangle) -> Option<C>,
    ) {
        self.begin_query();
        let record = self.record_hits;
        let Self {
            query,
            hits,
            contributions,
            points,
            ..
        } = self;
        let stats = mesh.bvh().descend(query, node, |t| {
            let found = mesh
                .mesh()
                .triangle(t as usize)
                .and_then(|tri| test(t, &tri));
            if let Some(c) = found {
                let first = points.len();
                push_contribution(contributions, points, c.normal(), c.depth(), 0, c.points());
                for p in &mut points[first..] {
                    p.feature = p.feature.of_part(t);
                }
                if record {
                    hits.push([t, NO_TRIANGLE]);
                }
            }
            ControlFlow::Continue(())
        });
        self.count(stats);
    }
}

/// One triangle's contact, as [`ContactScratch::collect_triangle_contacts`] pools it.
pub(crate) trait TriangleContact {
    /// Unit normal, from the triangle to the other shape.
    fn normal(&self) -> Vec3;
    /// Its separating depth.
    fn depth(&self) -> f32;
    /// Its candidate points.
    fn points(&self) -> &[ContactPoint];
}

impl TriangleContact for ContactManifold {
    fn normal(&self) -> Vec3 {
        self.normal
    }

    fn depth(&self) -> f32 {
        self.max_depth()
    }

    fn points(&self) -> &[ContactPoint] {
        ContactManifold::points(self)
    }
}

/// Adds a contribution and its points to the two pools (a free function, so that callers holding
/// other fields of the scratch can use it).
pub(crate) fn push_contribution(
    contributions: &mut Vec<Contribution>,
    pool: &mut Vec<ContactPoint>,
    normal: glam::Vec3,
    depth: f32,
    side: u8,
    points: &[ContactPoint],
) {
    // Pools hold far fewer than u32::MAX points: one query's candidates.
    contributions.push(Contribution {
        normal,
        depth,
        side,
        first: pool.len() as u32,
        count: points.len() as u32,
        apart: !points.is_empty() && points.iter().all(|p| p.depth < 0.0),
    });
    pool.extend_from_slice(points);
}

//! The query index: every collider's box in a [`ColliderTree`] (half-spaces aside, tested
//! directly), in three groups — the moving colliders, read at every update, and two groups read
//! only when the caller says they changed (a level's static scenery, sleeping bodies) — and the
//! queries a game asks — first hit and all hits of a ray, a cast of any convex shape, the
//! colliders overlapping a shape, the colliders containing a point, the nearest one — answered by
//! visiting only the boxes the query meets and testing those shapes exactly (the shape tests
//! of [`crate::ccd`] and [`crate::geometry::contacts`], meshes through their own hierarchies).
//!
//! The index stores boxes and ids, not shapes: each query reads the shapes it tests through a
//! [`ColliderLookup`] (the ECS's query, or a slice in the core's tests), and a filter closure
//! (layers, excluded entities) refuses candidates before any exact test. Results are
//! deterministic: hits at equal distances are ordered by id.

use super::box_cast::BoxCast;
use super::capsule_cast::CapsuleCast;
use super::cast::{CastHit, QueryError, Ray, cast_sphere, check_max_distance};
use super::collider_tree::ColliderTree;
use super::nearest::{PointHit, nearest_point};
use super::shape_cast::{ShapeCast, cast_shape, castable};
use super::tree::RaySegment;
use crate::bounding::Aabb;
use crate::bvh::QueryScratch;
use crate::ccd::CONTACT_TOLERANCE_RELATIVE;
use crate::geometry::contacts::{ContactScratch, contact_with_scratch};
use crate::geometry::{Isometry, Shape};
use glam::Vec3;

/// Where the queries read the colliders they test.
pub trait ColliderLookup {
    /// Collider `id`'s shape and world pose; `None` if it is gone (it is then skipped).
    fn collider(&self, id: u32) -> Option<(&Shape, Isometry)>;
}

impl ColliderLookup for [(Shape, Isometry)] {
    fn collider(&self, id: u32) -> Option<(&Shape, Isometry)> {
        self.get(id as usize).map(|(s, p)| (s, *p))
    }
}

/// A hit of a ray or a cast: which collider, and where.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QueryHit {
    /// The collider's id in the index.
    pub id: u32,
    /// Where, how far, and the surface normal.
    pub hit: CastHit,
}

/// How the last [`SpatialIndex::update`] kept the tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IndexUpdate {
    /// The same colliders in the same order: boxes refitted, `O(n)`.
    Refitted,
    /// Colliders came or went, a few: the tree kept, the new ones in a small tree of their
    /// own and the gone ones retired (see [`ColliderTree`]).
    Updated,
    /// Colliders came or went, many (or the first time): tree rebuilt, `O(n log n)`.
    Rebuilt,
}

/// The colliders' boxes, in three groups, and the buffers of the queries.
///
/// The *moving* group is read whole at every [`Self::update`]; the *still* group only when
/// [`Self::update_still`] is called and the *sleeping* group only when [`Self::update_sleeping`]
/// is, which a caller does when it knows a collider of the group changed: the ECS puts the
/// static bodies nobody wrote to since the last step in the still group (its settled statics),
/// so that a level's scenery costs nothing per step (Avian keeps static colliders in a tree of
/// their own for the same reason), and sleeping bodies in the sleeping group, read when a body
/// falls asleep or wakes. Two kept groups, not one: bodies fall asleep and wake far more often
/// than a level's scenery changes, and each time only the sleepers are read again. Queries
/// search every group, so ids must be unique across them.
#[derive(Debug, Default)]
pub struct SpatialIndex {
    /// The moving, still and sleeping groups, searched in that order.
    groups: [Group; 3],
    items: Vec<(u32, Aabb)>,
    node_stack: Vec<u32>,
    ray_stack: Vec<(u32, f32)>,
    candidates: Vec<u32>,
    mesh: QueryScratch,
    contact: ContactScratch,
}

/// The groups' places in [`SpatialIndex::groups`].
const MOVING: usize = 0;
const STILL: usize = 1;
const SLEEPING: usize = 2;

/// One group of colliders: a tree over the bounded ones and the list of the others.
#[derive(Debug, Default)]
struct Group {
    tree: ColliderTree,
    /// Half-spaces (and any shape with a box that is not finite): tested by every query.
    unbounded: Vec<u32>,
}

impl Group {
    /// Takes the group's colliders anew: see [`SpatialIndex::update`]. `items` is scratch.
    fn update<'a>(
        &mut self,
        colliders: impl IntoIterator<Item = (u32, &'a Shape, Isometry)>,
        items: &mut Vec<(u32, Aabb)>,
    ) -> IndexUpdate {
        items.clear();
        self.unbounded.clear();
        // While the ids are the last update's in order (most steps), each box goes straight
        // into the tree; at the first other id the items so far are collected and the rest
        // follows into the list `ColliderTree::update` takes.
        let mut streamed = Some(0);
        // `for_each`, not a `for` loop: the adapters' closures inline into this one and each
        // pose stays in registers (a `for` loop moved it through the stack, and reading it back
        // stalled on the stores: half of a refit's time).
        colliders.into_iter().for_each(|(id, shape, pose)| {
            let aabb = shape.world_aabb(&pose);
            if !(aabb.is_valid() && aabb.is_finite()) {
                self.unbounded.push(id);
            } else if let Some(at) = streamed {
                if self.tree.stream_box(at, id, &aabb) {
                    streamed = Some(at + 1);
                } else {
                    streamed = None;
                    self.tree.last_items(at, items);
                    items.push((id, aabb));
                }
            } else {
                items.push((id, aabb));
            }
        });
        if let Some(count) = streamed {
            if self.tree.finish_stream(count) {
                return IndexUpdate::Refitted;
            }
            self.tree.last_items(count, items);
        }
        self.tree.update(items)
    }

    fn len(&self) -> usize {
        self.tree.len() + self.unbounded.len()
    }
}

impl SpatialIndex {
    /// Indexes the moving group's `colliders` (`id`, shape, world pose), keeping the other
    /// groups as they are. Ids that stay with their colliders (the ECS's stable ids) let a change
    /// of a few colliders keep the tree: see [`ColliderTree::update`].
    pub fn update<'a>(
        &mut self,
        colliders: impl IntoIterator<Item = (u32, &'a Shape, Isometry)>,
    ) -> IndexUpdate {
        self.groups[MOVING].update(colliders, &mut self.items)
    }

    /// Indexes the still group's `colliders` as [`Self::update`] does the moving group's;
    /// their ids must differ from the other groups'.
    pub fn update_still<'a>(
        &mut self,
        colliders: impl IntoIterator<Item = (u32, &'a Shape, Isometry)>,
    ) -> IndexUpdate {
        self.groups[STILL].update(colliders, &mut self.items)
    }

    /// Indexes the sleeping group's `colliders` as [`Self::update`] does the moving group's;
    /// their ids must differ from the other groups'.
    pub fn update_sleeping<'a>(
        &mut self,
        colliders: impl IntoIterator<Item = (u32, &'a Shape, Isometry)>,
    ) -> IndexUpdate {
        self.groups[SLEEPING].update(colliders, &mut self.items)
    }

    /// How much the boxes are grown for a cast: the exact tests accept hits within
    /// [`SphereSweep::tolerance`](crate::ccd::SphereSweep::tolerance) of a shape, relative to
    /// the sweep's length, which is at most the distance across the tree's boxes; grown by it,
    /// no box culls a shape the exact test would hit.
    fn slack(&self, ray: &Ray, radius: f32, max: f32) -> f32 {
        let bounds = (self.groups.iter()).fold(Aabb::EMPTY, |b, g| b.union(&g.tree.bounds()));
        let across = (ray.origin() - bounds.center()).length() + bounds.half_extents().length();
        let length = if across.is_finite() {
            across.min(max)
        } else {
            max
        };
        2.0 * CONTACT_TOLERANCE_RELATIVE * (radius + length + 1.0)
    }

    /// Colliders indexed (bounded and unbounded, every group).
    pub fn len(&self) -> usize {
        self.groups.iter().map(Group::len).sum()
    }

    /// Whether nothing is indexed.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The nearest collider `accept`ed that `ray` hits within `max_distance`.
    pub fn cast_ray<L: ColliderLookup + ?Sized>(
        &mut self,
        colliders: &L,
        ray: &Ray,
        max_distance: f32,
        accept: impl FnMut(u32) -> bool,
    ) -> Result<Option<QueryHit>, QueryError> {
        self.cast_sphere(colliders, ray, 0.0, max_distance, accept)
    }

    /// The nearest collider `accept`ed that a sphere of `radius` moving along `ray` meets
    /// within `max_distance` (`radius` 0: a ray).
    pub fn cast_sphere<L: ColliderLookup + ?Sized>(
        &mut self,
        colliders: &L,
        ray: &Ray,
        radius: f32,
        max_distance: f32,
        accept: impl FnMut(u32) -> bool,
    ) -> Result<Option<QueryHit>, QueryError> {
        let max = check_max_distance(max_distance)?;
        check_radius(radius)?;
        let grow = radius + self.slack(ray, radius, max);
        Ok(self.first_hit(ray, grow, max, accept, |id, mesh| {
            exact_cast(colliders, id, ray, radius, max, mesh)
        }))
    }

    /// The nearest collider `accept`ed that `cast`'s box meets (see
    /// [`cast_box`](super::cast_box); its
    /// direction must be unit): [`Self::cast_shape`] with the box.
    pub fn cast_box<L: ColliderLookup + ?Sized>(
        &mut self,
        colliders: &L,
        cast: &BoxCast,
        accept: impl FnMut(u32) -> bool,
    ) -> Result<Option<QueryHit>, QueryError> {
        let motion = (cast.pose, cast.direction, cast.max_distance);
        self.cast_as(colliders, &Shape::cuboid(cast.half_extents), motion, accept)
    }

    /// The nearest collider `accept`ed that `cast`'s capsule meets (see
    /// [`cast_capsule`](super::cast_capsule); its direction must be unit): [`Self::cast_shape`]
    /// with the capsule.
    pub fn cast_capsule<L: ColliderLookup + ?Sized>(
        &mut self,
        colliders: &L,
        cast: &CapsuleCast,
        accept: impl FnMut(u32) -> bool,
    ) -> Result<Option<QueryHit>, QueryError> {
        let motion = (cast.pose, cast.direction, cast.max_distance);
        self.cast_as(colliders, &Shape::Capsule(cast.capsule), motion, accept)
    }

    /// [`Self::cast_shape`] of `shape` from `pose` along `direction` for at most `max_distance`.
    fn cast_as<L: ColliderLookup + ?Sized>(
        &mut self,
        colliders: &L,
        shape: &Shape,
        (pose, direction, max_distance): (Isometry, Vec3, f32),
        accept: impl FnMut(u32) -> bool,
    ) -> Result<Option<QueryHit>, QueryError> {
        let cast = ShapeCast {
            pose,
            shape,
            direction,
            max_distance,
        };
        self.cast_shape(colliders, &cast, accept)
    }

    /// The nearest collider `accept`ed that `cast`'s shape meets (see [`cast_shape`]: any
    /// convex shape; its direction must be unit); the tree is walked along the shape's path,
    /// its boxes grown by the shape's bounding radius. A half-space or a mesh is refused.
    pub fn cast_shape<L: ColliderLookup + ?Sized>(
        &mut self,
        colliders: &L,
        cast: &ShapeCast,
        accept: impl FnMut(u32) -> bool,
    ) -> Result<Option<QueryHit>, QueryError> {
        let max = check_max_distance(cast.max_distance)?;
        if !castable(cast.shape) {
            return Err(QueryError::NotCastable);
        }
        let (ray, grow) = self.shape_cast_start(cast.shape, &cast.pose, cast.direction, max)?;
        Ok(self.first_hit(&ray, grow, max, accept, |id, mesh| {
            let (shape, pose) = colliders.collider(id)?;
            cast_shape(cast, shape, &pose, mesh)
        }))
    }

    /// The checks of a shape cast (a finite start, a usable `shape` — reported by its
    /// numbers when not, see [`QueryError::BadSize`] — and a unit direction), then the ray its
    /// centre follows and how much the tree's boxes grow to hold the shape along it.
    fn shape_cast_start(
        &self,
        shape: &Shape,
        pose: &Isometry,
        direction: Vec3,
        max: f32,
    ) -> Result<(Ray, f32), QueryError> {
        if !pose.is_finite() {
            return Err(QueryError::NonFiniteOrigin(pose.translation));
        }
        if shape.validate().is_err() {
            let size = match shape {
                Shape::Cuboid(c) => c.half_extents,
                Shape::Capsule(c) => Vec3::new(c.half_length, c.radius, 0.0),
                Shape::Sphere(s) => Vec3::new(s.radius, 0.0, 0.0),
                Shape::Cylinder(c) => Vec3::new(c.half_height, c.radius, 0.0),
                Shape::Cone(c) => Vec3::new(c.half_height, c.radius, 0.0),
                Shape::Ellipsoid(e) => e.radii,
                _ => Vec3::splat(shape.bounding_radius()),
            };
            return Err(QueryError::BadSize(size));
        }
        if !direction.is_normalized() {
            return Err(QueryError::BadDirection(direction));
        }
        let ray = Ray::new(pose.translation, direction)?;
        let radius = shape.bounding_radius();
        Ok((ray, radius + self.slack(&ray, radius, max)))
    }

    /// The walk shared by the first-hit casts: every unbounded collider, then the tree's boxes
    /// grown by `grow` in the order `ray` enters them, each candidate `accept`ed tested by
    /// `exact`; boxes entered beyond the nearest hit so far are skipped. Ties go to the lower
    /// id.
    fn first_hit(
        &mut self,
        ray: &Ray,
        grow: f32,
        max: f32,
        mut accept: impl FnMut(u32) -> bool,
        mut exact: impl FnMut(u32, &mut QueryScratch) -> Option<CastHit>,
    ) -> Option<QueryHit> {
        let mut best: Option<QueryHit> = None;
        let mut consider = |id: u32, mesh: &mut QueryScratch| -> Option<f32> {
            if !accept(id) {
                return None;
            }
            // Cast to the query's own limit, not the nearest hit's, so that a shape's distance
            // does not depend on the order the tree found it in (the sweep's length scales it).
            if let Some(hit) = exact(id, mesh) {
                let nearer = best.is_none_or(|b| {
                    hit.distance < b.hit.distance || (hit.distance == b.hit.distance && id < b.id)
                });
                if nearer {
                    best = Some(QueryHit { id, hit });
                }
            }
            // Boxes entered beyond the nearest hit so far cannot hold a nearer one.
            best.map(|b| b.hit.distance)
        };
        let (groups, mesh) = (&self.groups, &mut self.mesh);
        for &id in groups.iter().flat_map(|g| &g.unbounded) {
            consider(id, mesh);
        }
        let segment = RaySegment::new(ray.origin(), ray.direction());
        // Each tree's walk starts from the nearest hit the walks before it found.
        let mut limit = max;
        for group in groups {
            limit = group
                .tree
                .along_ray(&segment, grow, limit, &mut self.ray_stack, |id, _| {
                    consider(id, mesh)
                });
        }
        best
    }

    /// Every collider `accept`ed that `ray` hits within `max_distance`, nearest first (ties by
    /// id), each once, in `out` (cleared first).
    pub fn cast_ray_all<L: ColliderLookup + ?Sized>(
        &mut self,
        colliders: &L,
        ray: &Ray,
        max_distance: f32,
        mut accept: impl FnMut(u32) -> bool,
        out: &mut Vec<QueryHit>,
    ) -> Result<(), QueryError> {
        let max = check_max_distance(max_distance)?;
        out.clear();
        let mut consider = |id: u32, mesh: &mut QueryScratch| {
            if accept(id)
                && let Some(hit) = exact_cast(colliders, id, ray, 0.0, max, mesh)
            {
                out.push(QueryHit { id, hit });
            }
        };
        let grow = self.slack(ray, 0.0, max);
        let (groups, mesh) = (&self.groups, &mut self.mesh);
        for &id in groups.iter().flat_map(|g| &g.unbounded) {
            consider(id, mesh);
        }
        let segment = RaySegment::new(ray.origin(), ray.direction());
        for group in groups {
            group
                .tree
                .along_ray(&segment, grow, max, &mut self.ray_stack, |id, _| {
                    consider(id, mesh);
                    None
                });
        }
        out.sort_by(|a, b| {
            a.hit
                .distance
                .total_cmp(&b.hit.distance)
                .then(a.id.cmp(&b.id))
        });
        Ok(())
    }

    /// The colliders `accept`ed that `shape` at `pose` touches or overlaps, ascending ids, in
    /// `out` (cleared first). Meshes are surfaces: a shape wholly inside a closed mesh does not
    /// touch it. Two half-spaces are never reported (no test covers the pair).
    pub fn overlapping<L: ColliderLookup + ?Sized>(
        &mut self,
        colliders: &L,
        (shape, pose): (&Shape, &Isometry),
        mut accept: impl FnMut(u32) -> bool,
        out: &mut Vec<u32>,
    ) {
        out.clear();
        self.candidates.clear();
        let query_box = shape.world_aabb(pose);
        for group in &self.groups {
            let candidates = &mut self.candidates;
            candidates.extend_from_slice(&group.unbounded);
            group
                .tree
                .overlapping(&query_box, &mut self.node_stack, |id| candidates.push(id));
        }
        for &id in &self.candidates {
            if !accept(id) {
                continue;
            }
            let Some((other, other_pose)) = colliders.collider(id) else {
                continue;
            };
            let touching =
                contact_with_scratch(shape, pose, other, &other_pose, &mut self.contact).is_some();
            if touching {
                out.push(id);
            }
        }
        out.sort_unstable();
        out.dedup();
    }

    /// The colliders `accept`ed holding `point` (inside or on a solid; on a mesh's surface),
    /// ascending ids, in `out` (cleared first).
    pub fn containing<L: ColliderLookup + ?Sized>(
        &mut self,
        colliders: &L,
        point: Vec3,
        accept: impl FnMut(u32) -> bool,
        out: &mut Vec<u32>,
    ) -> Result<(), QueryError> {
        if !point.is_finite() {
            return Err(QueryError::NonFiniteOrigin(point));
        }
        let at = Isometry::from_translation(point);
        self.overlapping(colliders, (&Shape::sphere(0.0), &at), accept, out);
        Ok(())
    }
}

impl SpatialIndex {
    /// The collider `accept`ed nearest to `point` within `max_distance` (inside a solid counts
    /// as distance 0; ties go to the lower id), with where it was met; see
    /// [`nearest_point`]. Visits boxes nearest first and stops once no box
    /// is nearer than the best collider found.
    pub fn nearest<L: ColliderLookup + ?Sized>(
        &mut self,
        colliders: &L,
        point: Vec3,
        max_distance: f32,
        mut accept: impl FnMut(u32) -> bool,
    ) -> Result<Option<(u32, PointHit)>, QueryError> {
        if !point.is_finite() {
            return Err(QueryError::NonFiniteOrigin(point));
        }
        check_max_distance(max_distance)?;
        let mut best: Option<(u32, PointHit)> = None;
        let mesh = &mut self.mesh;
        let mut consider = |id: u32| -> Option<f32> {
            if !accept(id) {
                return None;
            }
            let (shape, pose) = colliders.collider(id)?;
            let hit = nearest_point(shape, &pose, point, mesh);
            let better = best.is_none_or(|(b, h)| {
                hit.distance < h.distance || (hit.distance == h.distance && id < b)
            });
            if better && hit.distance <= max_distance {
                best = Some((id, hit));
                return Some(hit.distance * hit.distance);
            }
            None
        };
        let mut max2 = max_distance * max_distance;
        let groups = &self.groups;
        for &id in groups.iter().flat_map(|g| &g.unbounded) {
            if let Some(d2) = consider(id) {
                max2 = max2.min(d2);
            }
        }
        for group in groups {
            max2 = group
                .tree
                .near_point(point, max2, &mut self.ray_stack, |id, _| consider(id));
        }
        Ok(best)
    }
}

/// Refuses a cast radius that is negative or not finite.
fn check_radius(radius: f32) -> Result<(), QueryError> {
    if radius.is_finite() && radius >= 0.0 {
        Ok(())
    } else {
        Err(QueryError::BadRadius(radius))
    }
}

/// The cast of collider `id` (looked up) within `max`.
fn exact_cast<L: ColliderLookup + ?Sized>(
    colliders: &L,
    id: u32,
    ray: &Ray,
    radius: f32,
    max: f32,
    mesh: &mut QueryScratch,
) -> Option<CastHit> {
    let (shape, pose) = colliders.collider(id)?;
    let aabb = shape.world_aabb(&pose);
    cast_sphere(ray, radius, max, (shape, &pose, &aabb), mesh)
}

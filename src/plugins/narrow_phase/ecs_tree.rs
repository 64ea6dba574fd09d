//! A body's hierarchy (the scene graph under it) seen through the ECS, as the pair descent of
//! [`crate::hierarchy`] reads it: its nodes' volumes, each grown by half a pair's speculative
//! margin, and their children.

use crate::bounding::Aabb;
use crate::components::*;
use crate::hierarchy::BvTree;
use bevy_ecs::prelude::*;

/// What the descent reads of a node: its collider, pose, subtree volume and children.
pub(super) type Node<'a> = (
    Option<Ref<'a, Collider>>,
    &'a GlobalPose,
    &'a BoundingVolume,
    Option<&'a Children>,
);

/// A body's hierarchy, seen through the ECS, for the pair descent of [`crate::hierarchy`];
/// its volumes grown by `grow` (half a pair's speculative margin: two volumes each grown by
/// half of it meet when the parts are within the margin).
pub(super) struct EcsTree<'q, 'w, 's, 'd> {
    pub(super) nodes: &'q Query<'w, 's, Node<'d>, Without<Quarantined>>,
    pub(super) grow: f32,
}

impl EcsTree<'_, '_, '_, '_> {
    fn grown(&self, b: Aabb) -> Aabb {
        if self.grow > 0.0 && b.is_valid() {
            b.expanded(self.grow)
        } else {
            b
        }
    }
}

impl BvTree for EcsTree<'_, '_, '_, '_> {
    type Node = Entity;

    fn subtree_bv(&self, n: Entity) -> Aabb {
        self.grown(self.nodes.get(n).map_or(Aabb::EMPTY, |(_, _, bv, _)| bv.0))
    }

    fn own_bv(&self, n: Entity) -> Option<Aabb> {
        let (collider, global, ..) = self.nodes.get(n).ok()?;
        collider.map(|c| self.grown(c.shape.world_aabb(&global.0)))
    }

    fn children(&self, n: Entity, out: &mut Vec<Entity>) {
        if let Ok((.., Some(children))) = self.nodes.get(n) {
            out.extend(children.iter());
        }
    }
}

//! Colliders spawned under plain scene entities: a Bevy level is often a tree of entities with
//! only a `Transform` (a scene root, a group), its colliders at the leaves. urto's hierarchy
//! places a part relative to its `ChildOf` parent's [`Position`], so such a parent would leave
//! its colliders where their local poses alone put them (a static wall drawn at x = 10 but
//! colliding at x = 0), and the parent itself would be quarantined as a root without a pose.
//!
//! Instead, a plain entity (no `Position`, no `Velocity`) with a placed entity among its
//! children takes a [`Position`] and [`Rotation`] from its `Transform` (identity without one),
//! and so does each plain ancestor above it up to the first placed one: a plain root becomes
//! a static compound root where the game draws it (Avian places such colliders by their
//! `GlobalTransform` too), and writing its `Transform` later moves its colliders, as any
//! static body's. A body with its own `Velocity` under such a root is still a part with a
//! velocity, quarantined with a warning saying so: a moving body must be a root.

use crate::components::{Position, Quarantined, Rotation, Velocity};
use crate::plugins::validation::MAX_HIERARCHY_DEPTH;
use bevy_ecs::entity::EntityHashSet;
use bevy_ecs::prelude::*;
use bevy_transform::components::Transform;

type PlainAncestor<'a> = (Option<&'a Transform>, Option<&'a ChildOf>);
/// Placed entities given a parent since the last step.
type NewlyParented = (Changed<ChildOf>, With<Position>, Without<Quarantined>);

/// Gives the plain ancestors of newly parented placed entities a pose from their `Transform`.
pub(crate) fn place_plain_parents(
    parts: Query<&ChildOf, NewlyParented>,
    plain: Query<PlainAncestor, (Without<Position>, Without<Velocity>)>,
    mut placed: Local<EntityHashSet>,
    mut commands: Commands,
) {
    placed.clear();
    for child_of in &parts {
        let mut up = child_of.parent();
        // A loop of plain parents is cut short here and quarantined by validation.
        for _ in 0..MAX_HIERARCHY_DEPTH {
            let Ok((transform, parent)) = plain.get(up) else {
                break;
            };
            if !placed.insert(up) {
                break;
            }
            let t = transform.copied().unwrap_or_default();
            commands
                .entity(up)
                .insert((Position(t.translation), Rotation(t.rotation)));
            match parent {
                Some(p) => up = p.parent(),
                None => break,
            }
        }
    }
}

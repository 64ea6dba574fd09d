//! A swept body's convex parts, and which of them meet an obstacle: what refines a sweep's
//! sphere to the body's own shape ([`crate::ccd::toi_parts_from`]), for the sweeps against
//! scenery (`mod.rs`) and against moving bodies (`movers.rs`).

use super::Obstacle;
use crate::ccd::{MAX_REFINED_PARTS, ShapeOnSweep};
use crate::components::*;
use crate::geometry::{Isometry, Shape};
use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use std::borrow::Cow;

/// A node's pose in its parent's frame.
pub(super) type NodePose<'a> = (Option<&'a Position>, Option<&'a Rotation>);

/// The convex colliders of `body` (its own and its descendants', sensors left out) placed in
/// its frame on its sweep turning by `rotations`, into `parts` (their layers into
/// `part_layers`); left empty where refining cannot help: a body turning too fast for the slerp
/// between its two orientations to be the way it turned (`rotations` is `None`), one that is
/// one ball about its swept centre (its sweep is exact), or one with a part that has no finite
/// convex gap (a mesh) or more than [`MAX_REFINED_PARTS`] parts. Each part's place in the body
/// is composed from the nodes' local poses down from the root, not taken from world poses (whose
/// f32 rounding far from the origin would move a part by millimetres).
pub(super) fn parts_on_sweep<'q>(
    body: Entity,
    (rotations, local_center): (Option<[Quat; 2]>, Vec3),
    obstacles: &'q Query<Obstacle, Without<Quarantined>>,
    locals: &Query<NodePose, With<ChildOf>>,
    stack: &mut Vec<(Entity, Isometry)>,
    (parts, part_layers): (&mut Vec<ShapeOnSweep<'q>>, &mut Vec<CollisionLayers>),
) {
    parts.clear();
    part_layers.clear();
    let Some(rotations) = rotations else {
        return;
    };
    stack.clear();
    stack.push((body, Isometry::IDENTITY));
    while let Some((node, in_body)) = stack.pop() {
        let Ok((collider, _, _, children, _, layers, sensor)) = obstacles.get(node) else {
            continue;
        };
        push_children(children, &in_body, locals, stack);
        let Some(c) = collider.filter(|_| !sensor) else {
            continue;
        };
        if !ShapeOnSweep::has_convex_gap(&c.shape) || parts.len() == MAX_REFINED_PARTS {
            parts.clear();
            part_layers.clear();
            return;
        }
        parts.push(ShapeOnSweep::part(
            &c.shape,
            &in_body,
            rotations,
            local_center,
        ));
        part_layers.push(layers_of(layers));
    }
    if let [only] = parts.as_slice()
        && matches!(only.shape, Shape::Sphere(_))
        && only.local_center == Vec3::ZERO
    {
        parts.clear();
        part_layers.clear();
    }
}

/// Pushes a node's `children` onto `stack`, each with its pose composed onto the node's `pose`
/// (poses in the frame the walk started from, composed down from the root: no world pose's
/// rounding far from the origin).
pub(super) fn push_children(
    children: Option<&Children>,
    pose: &Isometry,
    locals: &Query<NodePose, With<ChildOf>>,
    stack: &mut Vec<(Entity, Isometry)>,
) {
    for child in children.into_iter().flat_map(|c| c.iter()) {
        let (p, r) = locals.get(child).unwrap_or((None, None));
        let local = Isometry::new(p.map_or(Vec3::ZERO, |p| p.0), Rotation::of(r));
        stack.push((child, *pose * local));
    }
}

/// A body's convex parts on its sweep and each one's collision layers.
pub(super) type LayeredParts<'p, 'q> = (&'p [ShapeOnSweep<'q>], &'p [CollisionLayers]);

/// The parts that meet an obstacle in `obstacle` layers: all of them when each one's layers
/// interact with it (the common case, borrowed), those that do when some do not, `None` when
/// none does. Without parts (a body not refined), the body's own `layers` decide, and the
/// answer is an empty list or `None`.
pub(super) fn meeting_parts<'p, 'q>(
    (parts, part_layers): LayeredParts<'p, 'q>,
    layers: CollisionLayers,
    obstacle: &CollisionLayers,
) -> Option<Cow<'p, [ShapeOnSweep<'q>]>> {
    if parts.is_empty() {
        return layers
            .interacts_with(obstacle)
            .then_some(Cow::Borrowed(parts));
    }
    let meets = |l: &CollisionLayers| l.interacts_with(obstacle);
    if part_layers.iter().all(meets) {
        return Some(Cow::Borrowed(parts));
    }
    let some: Vec<_> = parts
        .iter()
        .zip(part_layers)
        .filter(|(_, l)| meets(l))
        .map(|(p, _)| *p)
        .collect();
    (!some.is_empty()).then_some(Cow::Owned(some))
}

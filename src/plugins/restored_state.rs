//! Puts back the state urto keeps on a body when a game removes it. A body's [`GlobalPose`]
//! and [`BoundingVolume`] are required by its [`Position`] and written by the hierarchy stage
//! only; Bevy inserts required components at spawn, not after a removal. A game that removed
//! one (by mistake, or clearing components it did not know) left the body out of the broad
//! phase for good: a resting stack whose volumes were removed fell through its slab, with no
//! word (a user-style probe). Each is put back with a warning, and the body's poses marked
//! changed so that the hierarchy stage recomputes both in the same step: a settled static
//! loses its marker (the change scans leave settled bodies out, `settle.rs`) and a sleeper
//! wakes (sleepers are left out too).

use crate::components::*;
use crate::plugins::settle::Settled;
use bevy_ecs::prelude::*;

/// A removed [`GlobalPose`] or [`BoundingVolume`], put back on a body that still has its
/// [`Position`] (a despawned one is let go).
pub(crate) fn restore_removed_state(
    mut volumes: RemovedComponents<BoundingVolume>,
    mut poses: RemovedComponents<GlobalPose>,
    mut bodies: Query<(&mut Position, Option<&mut GlobalPose>, Has<BoundingVolume>)>,
    mut commands: Commands,
) {
    for e in volumes.read().chain(poses.read()) {
        let Ok((mut position, pose, has_volume)) = bodies.get_mut(e) else {
            continue;
        };
        let has_pose = pose.is_some();
        if has_volume && has_pose {
            continue;
        }
        log::warn!(
            "urto: {e}: its GlobalPose or BoundingVolume was removed; urto keeps them (put back)"
        );
        // The pose propagated again may be the same value, which marks nothing: the volume's
        // refit reads a changed pose.
        position.set_changed();
        if let Some(mut pose) = pose {
            pose.set_changed();
        }
        let mut entity = commands.entity(e);
        entity.remove::<(Settled, Sleeping)>();
        if !has_volume {
            entity.insert(BoundingVolume::default());
        }
        if !has_pose {
            entity.insert(GlobalPose::default());
        }
    }
}

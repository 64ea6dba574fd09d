//! Mirrors physics poses into Bevy's `Transform`, so a game renders what urto simulates.
//!
//! urto keeps its own [`Position`] and [`Rotation`] (f32, the physics' truth, unaffected by
//! render-only scaling or interpolation); after each step this writes them into the `Transform`
//! of every body that has one. Both are relative to the parent, so Bevy's own transform
//! propagation composes them exactly as urto's hierarchy does. Bodies without a `Transform`
//! cost nothing, and a world with none does not run the system at all.

use crate::components::{Position, Quarantined, Rotation, Sleeping};
use crate::schedule::{PhysicsSchedule, PhysicsSet};
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_transform::components::Transform;

/// Copies `Position`/`Rotation` into `Transform` at the end of every physics step.
#[derive(Debug, Clone, Default)]
pub struct TransformSyncPlugin;

impl Plugin for TransformSyncPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            PhysicsSchedule,
            sync_transforms
                .run_if(any_with_component::<Transform>)
                .in_set(PhysicsSet::Debug),
        );
    }
}

type Moved = (
    Or<(Changed<Position>, Changed<Rotation>)>,
    Without<Quarantined>,
    Without<Sleeping>,
);

fn sync_transforms(mut bodies: Query<(&Position, &Rotation, &mut Transform), Moved>) {
    for (p, r, mut t) in &mut bodies {
        if t.translation != p.0 || t.rotation != r.0 {
            t.translation = p.0;
            t.rotation = r.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prelude::*;
    use glam::Vec3;

    #[test]
    fn transforms_follow_the_simulation_and_keep_their_scale() {
        let mut app = App::new();
        app.add_plugins(UrtoPlugins::default());
        let e = app
            .world_mut()
            .spawn((
                Velocity::new(6.0, 0.0, 0.0),
                Transform::from_scale(Vec3::splat(2.0)),
            ))
            .id();
        crate::step(app.world_mut(), 10).unwrap();
        let t = app.world().get::<Transform>(e).unwrap();
        assert!((t.translation.x - 1.0).abs() < 1e-5, "{}", t.translation);
        assert_eq!(t.scale, Vec3::splat(2.0));
    }
}

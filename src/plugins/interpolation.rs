//! Rendered poses between fixed steps: a body marked [`TransformInterpolation`] is drawn at
//! `lerp(previous, current, α)` (positions) and `slerp` (rotations), where `α` is how far the
//! frame's time is into the next fixed step (`Time<Fixed>::overstep_fraction`), so a game
//! rendering at 144 Hz over a 60 Hz physics sees smooth motion instead of a pose that jumps
//! once every two or three frames (Avian's and bevy_rapier's transform interpolation; Glenn
//! Fiedler, "Fix your timestep!", 2004).
//!
//! The physics' truth ([`Position`], [`Rotation`]) is untouched: only `Transform`, the render
//! side, is blended, one step behind at most. Each step records the pose it starts from; until
//! a body has taken a step it is drawn where it is. A body a game teleports by writing its
//! `Transform` is moved there at once (the write is taken as the body's new pose, as
//! `transform_sync.rs` explains, and not blended away); one teleported by writing its
//! `Position` is drawn sliding there over one step. Bodies without the marker pay nothing.

use crate::components::{Position, Quarantined, Rotation};
use crate::plugins::core::PrepareWake;
use crate::plugins::transform_sync::{ReadGameTransforms, TransformWritten};
use crate::schedule::{PhysicsSchedule, PhysicsSet};
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_time::{Fixed, Time};
use bevy_transform::TransformSystems;
use bevy_transform::components::Transform;
use glam::{Quat, Vec3};

/// Blends rendered transforms between fixed steps for bodies that ask for it.
#[derive(Debug, Clone, Default)]
pub struct InterpolationPlugin;

/// Draw this body between its last two physics poses (opt-in per entity; needs a `Transform`).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
#[require(PreviousPose)]
pub struct TransformInterpolation;

/// The pose a body had when the last physics step began (`None` before its first step).
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct PreviousPose(pub Option<(Vec3, Quat)>);

impl Plugin for InterpolationPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            PhysicsSchedule,
            record_previous_poses
                .run_if(any_with_component::<TransformInterpolation>)
                .in_set(PhysicsSet::Prepare)
                .after(ReadGameTransforms)
                .before(PrepareWake),
        )
        .add_systems(
            PostUpdate,
            interpolate_transforms
                .run_if(any_with_component::<TransformInterpolation>)
                .before(TransformSystems::Propagate),
        );
    }
}

fn record_previous_poses(
    mut bodies: Query<(&Position, Option<&Rotation>, &mut PreviousPose), Without<Quarantined>>,
) {
    for (p, r, mut previous) in &mut bodies {
        let rotation = Rotation::of(r);
        previous.set_if_neq(PreviousPose(Some((p.0, rotation))));
    }
}

type Drawn<'a> = (
    Entity,
    &'a mut Position,
    Option<&'a mut Rotation>,
    &'a mut PreviousPose,
    &'a mut Transform,
    Option<&'a mut TransformWritten>,
);

fn interpolate_transforms(
    mut bodies: Query<Drawn, (With<TransformInterpolation>, Without<Quarantined>)>,
    fixed: Option<Res<Time<Fixed>>>,
    mut commands: Commands,
) {
    // Without Bevy's fixed clock (a world stepped by `urto::step`) there is no frame between
    // steps: draw the current pose.
    let alpha = fixed.map_or(1.0, |t| t.overstep_fraction().clamp(0.0, 1.0));
    for (e, mut p, r, mut previous, mut t, written) in &mut bodies {
        let mut current = (p.0, Rotation::of(r.as_deref()));
        if written.as_ref().is_some_and(|w| !w.holds(&t)) {
            // The game moved the body since the last frame: that is its pose now, drawn as is.
            current = (t.translation, t.rotation);
            p.0 = t.translation;
            match r {
                Some(mut r) => r.0 = t.rotation,
                None if t.rotation != Quat::IDENTITY => {
                    commands.entity(e).insert(Rotation(t.rotation));
                }
                None => {}
            }
            previous.0 = None;
        }
        let (translation, rotation) = match previous.0 {
            Some((p0, q0)) => (p0.lerp(current.0, alpha), q0.slerp(current.1, alpha)),
            None => current,
        };
        let written = written.map(Mut::into_inner);
        if let Some(first) = TransformWritten::write(written, &mut t, translation, rotation) {
            commands.entity(e).insert(first);
        }
    }
}

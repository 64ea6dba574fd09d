//! Keeps Bevy's `Transform` and urto's pose in step, both ways, so a game renders what urto
//! simulates and can move a body by writing its `Transform`.
//!
//! urto keeps its own [`Position`] and [`Rotation`] (f32, the physics' truth, unaffected by
//! render-only scaling or interpolation). Both directions are relative to the parent, so Bevy's
//! own transform propagation composes them exactly as urto's hierarchy does:
//!
//! - **Physics to render**: after each step, the pose of every body that moved is written into
//!   its `Transform` (scale untouched).
//! - **Game to physics**: before each step, a `Transform` the game changed becomes the body's
//!   pose (a teleport: velocities are kept, a sleeping body wakes). urto remembers what it wrote
//!   last ([`TransformWritten`]), so its own writes — and the interpolation's — are not mistaken
//!   for the game's, as Avian's `transform_to_position` does by comparison.
//! - **At spawn**, an explicitly set `Position` or `Rotation` wins, and is copied into the
//!   `Transform` at once (a body spawned with a `Position` was drawn at the origin until the
//!   first step ran, up to three frames at 200 frames a second); a body spawned with only a
//!   `Transform` (the usual Bevy way) starts where that `Transform` puts it.
//!
//! Bodies without a `Transform` cost nothing, and a world with none does not run the systems.

use crate::components::{Position, Quarantined, Rotation, Sleeping};
use crate::plugins::settle::Unsettled;
use crate::schedule::{PhysicsSchedule, PhysicsSet};
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use bevy_transform::components::Transform;
use glam::{Quat, Vec3};

/// Copies `Position`/`Rotation` into `Transform` at the end of every physics step, and a
/// `Transform` the game changed into `Position`/`Rotation` at the start of the next.
#[derive(Debug, Clone, Default)]
pub struct TransformSyncPlugin;

/// The system that reads the game's `Transform` writes, in [`PhysicsSet::Prepare`]: anything
/// that records a body's pose at the start of a step orders itself after it.
#[derive(SystemSet, Debug, Clone, PartialEq, Eq, Hash)]
pub struct ReadGameTransforms;

/// The translation and rotation urto last wrote into this body's `Transform` (by the step or by
/// interpolation): a `Transform` that differs from it was written by the game.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct TransformWritten {
    /// The translation written.
    pub translation: Vec3,
    /// The rotation written.
    pub rotation: Quat,
}

impl TransformWritten {
    /// True when `t` still holds what urto wrote (the game has not moved it).
    pub fn holds(&self, t: &Transform) -> bool {
        t.translation == self.translation && t.rotation == self.rotation
    }

    /// Writes `translation` and `rotation` into `t` (only if they differ, so that an unchanged
    /// body does not trigger Bevy's change detection) and remembers them.
    pub(crate) fn write(
        written: Option<&mut Self>,
        t: &mut Mut<Transform>,
        translation: Vec3,
        rotation: Quat,
    ) -> Option<Self> {
        if t.translation != translation || t.rotation != rotation {
            t.translation = translation;
            t.rotation = rotation;
        }
        let now = Self {
            translation,
            rotation,
        };
        match written {
            Some(w) => {
                *w = now;
                None
            }
            None => Some(now),
        }
    }
}

impl Plugin for TransformSyncPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            PhysicsSchedule,
            (
                read_game_transforms
                    .run_if(any_with_component::<Transform>)
                    .in_set(ReadGameTransforms)
                    .in_set(PhysicsSet::Prepare)
                    .before(crate::plugins::core::PrepareWake),
                sync_transforms
                    .run_if(any_with_component::<Transform>)
                    .in_set(PhysicsSet::Debug),
            ),
        )
        .add_observer(draw_spawned_pose);
    }
}

type GameWritten<'a> = (
    Entity,
    Ref<'a, Transform>,
    &'a mut Position,
    Option<&'a mut Rotation>,
    Option<&'a TransformWritten>,
);

/// The game-to-physics direction of the module notes.
fn read_game_transforms(
    mut bodies: Query<GameWritten, (Changed<Transform>, Without<Quarantined>, Unsettled)>,
    mut commands: Commands,
) {
    for (e, t, mut position, rotation, written) in &mut bodies {
        let moved_by_game = match written {
            Some(w) => !w.holds(&t),
            // Never written by urto: a spawn. The Transform places the body only when the
            // pose was left at its default.
            None => {
                let posed = position.0 != Vec3::ZERO
                    || rotation.as_ref().is_some_and(|r| r.0 != Quat::IDENTITY);
                !posed && (t.translation != Vec3::ZERO || t.rotation != Quat::IDENTITY)
            }
        };
        if !moved_by_game {
            continue;
        }
        if position.0 != t.translation {
            position.0 = t.translation;
        }
        match rotation {
            Some(mut r) if r.0 != t.rotation => r.0 = t.rotation,
            Some(_) => {}
            None if t.rotation != Quat::IDENTITY => {
                commands.entity(e).insert(Rotation(t.rotation));
            }
            None => {}
        }
    }
}

type Moved = (
    Or<(Changed<Position>, Changed<Rotation>)>,
    Without<Quarantined>,
    Without<Sleeping>,
    Unsettled,
);

type Drawn<'a> = (
    Entity,
    &'a Position,
    Option<&'a Rotation>,
    &'a mut Transform,
    Option<&'a mut TransformWritten>,
);

fn sync_transforms(mut bodies: Query<Drawn, Moved>, mut commands: Commands) {
    for (e, p, r, mut t, written) in &mut bodies {
        let rotation = Rotation::of(r);
        if let Some(first) =
            TransformWritten::write(written.map(Mut::into_inner), &mut t, p.0, rotation)
        {
            commands.entity(e).insert(first);
        }
    }
}

/// A body spawned with a `Position` or `Rotation` of its own is drawn there from its first
/// frame: its `Transform` takes that pose when either is added (one write per spawn, no
/// per-frame pass).
fn draw_spawned_pose(
    add: On<Add<(Position, Transform)>>,
    mut bodies: Query<(&Position, &Rotation, &mut Transform)>,
) {
    let Ok((p, r, mut t)) = bodies.get_mut(add.entity) else {
        return;
    };
    let posed = p.0 != Vec3::ZERO || r.0 != Quat::IDENTITY;
    if posed && (t.translation != p.0 || t.rotation != r.0) {
        t.translation = p.0;
        t.rotation = r.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prelude::*;
    use glam::Vec3;

    fn app() -> App {
        let mut app = App::new();
        app.add_plugins(UrtoPlugins::default());
        app
    }

    /// A ball of radius 0.5 at `at` moving at `v`, drawn by a `Transform` (left at its default).
    fn ball(app: &mut App, at: Vec3, v: Vec3) -> Entity {
        app.world_mut()
            .spawn((
                Collider::sphere(0.5),
                Position(at),
                Velocity(v),
                Transform::default(),
            ))
            .id()
    }

    #[test]
    fn transforms_follow_the_simulation_and_keep_their_scale() {
        let mut app = app();
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

    #[test]
    fn a_body_spawned_with_only_a_transform_starts_there_and_a_set_position_wins() {
        let mut app = app();
        let turned = Quat::from_rotation_z(0.5);
        let by_transform = app
            .world_mut()
            .spawn((
                Collider::sphere(0.5),
                Velocity::default(),
                Transform::from_xyz(3.0, -1.0, 5.0).with_rotation(turned),
            ))
            .id();
        let by_position = ball(&mut app, Vec3::new(-4.0, 0.0, 2.0), Vec3::ZERO);
        crate::step(app.world_mut(), 1).unwrap();
        let w = app.world();
        assert_eq!(
            w.get::<Position>(by_transform).unwrap().0,
            Vec3::new(3.0, -1.0, 5.0)
        );
        assert_eq!(w.get::<Rotation>(by_transform).unwrap().0, turned);
        assert_eq!(
            w.get::<Position>(by_position).unwrap().0,
            Vec3::new(-4.0, 0.0, 2.0)
        );
        assert_eq!(
            w.get::<Transform>(by_position).unwrap().translation,
            Vec3::new(-4.0, 0.0, 2.0)
        );
    }

    /// Drawn where it is from its first frame, before any step: the `Transform` of a body
    /// spawned with a `Position` and `Rotation` holds them at once (it held the origin until
    /// the first step); one spawned with only a `Transform` keeps it.
    #[test]
    fn a_body_spawned_with_a_position_is_drawn_there_before_any_step() {
        let mut app = app();
        let turned = Quat::from_rotation_y(0.3);
        let at = Vec3::new(0.0, 5.0, 1.0);
        let pose = (Position(at), Rotation(turned), Transform::default());
        let posed = app.world_mut().spawn((Collider::sphere(0.5), pose)).id();
        let drawn = Transform::from_xyz(2.0, 0.0, 0.0);
        let by_transform = app.world_mut().spawn((Collider::sphere(0.5), drawn)).id();
        let w = app.world();
        let t = w.get::<Transform>(posed).unwrap();
        assert_eq!((t.translation, t.rotation), (at, turned));
        assert_eq!(*w.get::<Transform>(by_transform).unwrap(), drawn);
        assert_eq!(w.get::<Position>(by_transform).unwrap().0, Vec3::ZERO);
    }

    #[test]
    fn a_game_writing_a_transform_teleports_the_body_and_keeps_its_velocity_to_1e_5() {
        let mut app = app();
        let e = ball(&mut app, Vec3::ZERO, Vec3::new(6.0, 0.0, 0.0));
        crate::step(app.world_mut(), 10).unwrap();
        let turned = Quat::from_rotation_x(1.0);
        {
            let mut t = app.world_mut().get_mut::<Transform>(e).unwrap();
            t.translation = Vec3::new(20.0, 5.0, 0.0);
            t.rotation = turned;
        }
        crate::step(app.world_mut(), 1).unwrap();
        let w = app.world();
        let p = w.get::<Position>(e).unwrap().0;
        assert!((p - Vec3::new(20.1, 5.0, 0.0)).length() < 1e-5, "{p}");
        assert!((w.get::<Velocity>(e).unwrap().0.x - 6.0).abs() < 1e-5);
        assert!(w.get::<Rotation>(e).unwrap().0.angle_between(turned) < 1e-5);
        // urto's own write is not a teleport: the next steps move on from there.
        crate::step(app.world_mut(), 5).unwrap();
        let p = app.world().get::<Position>(e).unwrap().0;
        assert!((p - Vec3::new(20.6, 5.0, 0.0)).length() < 1e-4, "{p}");
    }

    #[test]
    fn a_nan_transform_quarantines_its_body_only() {
        let mut app = app();
        let bad = app
            .world_mut()
            .spawn((
                Collider::sphere(0.5),
                Velocity::default(),
                Transform::default(),
            ))
            .id();
        let good = app
            .world_mut()
            .spawn((
                Collider::sphere(0.5),
                Position::new(0.9, 0.0, 0.0),
                Velocity::default(),
                Transform::default(),
            ))
            .id();
        crate::step(app.world_mut(), 1).unwrap();
        app.world_mut()
            .get_mut::<Transform>(bad)
            .unwrap()
            .translation
            .x = f32::NAN;
        crate::step(app.world_mut(), 3).unwrap();
        let w = app.world();
        assert!(w.get::<Quarantined>(bad).is_some());
        assert!(w.get::<Position>(good).unwrap().0.is_finite());
    }

    #[test]
    fn a_sleeping_body_moved_by_its_transform_wakes_and_falls_from_there() {
        let mut app = app();
        app.insert_resource(Gravity::EARTH_Z_UP);
        app.world_mut()
            .spawn((Collider::half_space(Vec3::Z), Static));
        let ball = ball(&mut app, Vec3::new(0.0, 0.0, 0.5), Vec3::ZERO);
        crate::step(app.world_mut(), 120).unwrap();
        assert!(
            app.world().get::<Sleeping>(ball).is_some(),
            "asleep at rest"
        );
        app.world_mut()
            .get_mut::<Transform>(ball)
            .unwrap()
            .translation = Vec3::new(1.0, 0.0, 3.0);
        crate::step(app.world_mut(), 1).unwrap();
        let w = app.world();
        assert!(w.get::<Sleeping>(ball).is_none());
        let p = w.get::<Position>(ball).unwrap().0;
        assert!((p.x - 1.0).abs() < 1e-6 && p.z < 3.0 && p.z > 2.9, "{p}");
    }

    #[test]
    fn an_interpolated_body_moved_by_its_transform_is_not_blended_back() {
        use crate::plugins::interpolation::TransformInterpolation;
        let mut app = app();
        let e = app
            .world_mut()
            .spawn((
                Collider::sphere(0.5),
                Velocity::new(6.0, 0.0, 0.0),
                Transform::default(),
                TransformInterpolation,
            ))
            .id();
        crate::step(app.world_mut(), 3).unwrap();
        app.world_mut().run_schedule(PostUpdate);
        app.world_mut().get_mut::<Transform>(e).unwrap().translation = Vec3::new(0.0, 9.0, 0.0);
        app.world_mut().run_schedule(PostUpdate);
        let w = app.world();
        assert_eq!(
            w.get::<Transform>(e).unwrap().translation,
            Vec3::new(0.0, 9.0, 0.0)
        );
        assert_eq!(w.get::<Position>(e).unwrap().0, Vec3::new(0.0, 9.0, 0.0));
        crate::step(app.world_mut(), 1).unwrap();
        let p = app.world().get::<Position>(e).unwrap().0;
        assert!((p - Vec3::new(0.1, 9.0, 0.0)).length() < 1e-5, "{p}");
    }
}

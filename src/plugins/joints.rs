//! Joints in the ECS: [`JointPlugin`] checks each [`Joint`], keeps the pairs of jointed bodies
//! that must not collide, and breaks joints that held more than their threshold. The joints are
//! solved by the rigid-body solver ([`SoftStepPlugin`](super::SoftStepPlugin)) with the
//! contacts, in the same substeps (see [`crate::dynamics::solver::joint`]); without the solver
//! they do nothing.
//!
//! A joint whose values are unusable, that names a body twice or a body that does not exist, has
//! no [`Position`] or is a part of a compound, is quarantined with a warning that says why (a
//! joint with a quarantined body is skipped, so nothing crosses from a bad body to a good one).

use crate::components::*;
use crate::plugins::core::PrepareStart;
use crate::plugins::soft_step::{SoftStepSolver, SolveBodies};
use crate::plugins::validation::quarantine;
use crate::schedule::{PhysicsSchedule, SubstepSchedule, SubstepSet};
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;

/// Joints: checks, collision filtering between jointed bodies, breaking (in
/// [`UrtoPlugins`](crate::UrtoPlugins)).
#[derive(Debug, Clone, Default)]
pub struct JointPlugin;

impl Plugin for JointPlugin {
    fn build(&self, app: &mut App) {
        app.add_message::<JointBroken>()
            .init_resource::<JointedPairs>()
            .add_systems(
                PhysicsSchedule,
                (quarantine_invalid_joints, collect_jointed_pairs)
                    .chain()
                    .in_set(PrepareStart),
            )
            .add_systems(
                SubstepSchedule,
                break_joints
                    .after(SolveBodies)
                    .in_set(SubstepSet::Response)
                    .run_if(resource_exists::<SoftStepSolver>),
            );
    }
}

/// The pairs of bodies a joint keeps from colliding (each as `(min, max)`, sorted); the narrow
/// phase skips them.
#[derive(Resource, Debug, Default)]
pub struct JointedPairs {
    pairs: Vec<(Entity, Entity)>,
    /// The pairs in the joints' iteration order, as last collected: while the joints are the
    /// same, so is this list, and the sort is skipped (a 10,000-ball net's 19,800 joints cost
    /// 4.8 million instructions a step to sort).
    collected: Vec<(Entity, Entity)>,
    /// This step's collection, compared with the last.
    scratch: Vec<(Entity, Entity)>,
}

impl JointedPairs {
    /// True when no joint filters a pair.
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }

    /// Whether a joint keeps `a` and `b` from colliding.
    pub fn contains(&self, a: Entity, b: Entity) -> bool {
        !self.pairs.is_empty() && self.pairs.binary_search(&(a.min(b), a.max(b))).is_ok()
    }
}

/// The joints the solver takes: not disabled, not quarantined.
pub(crate) type ActiveJoint = (Without<JointDisabled>, Without<Quarantined>);

/// Quarantines joints with unusable values (checked when the joint changes) or bodies (checked
/// every step: a body can vanish or become a part at any time, and it is two lookups).
fn quarantine_invalid_joints(
    joints: Query<(Entity, Ref<Joint>), ActiveJoint>,
    bodies: Query<Has<ChildOf>, With<Position>>,
    mut commands: Commands,
) {
    for (e, joint) in &joints {
        let ends = [Some(joint.body_a), joint.body_b_entity()];
        let body_problem = ends
            .into_iter()
            .flatten()
            .find_map(|b| match bodies.get(b) {
                Err(_) => Some(format!("body {b} does not exist or has no Position")),
                Ok(true) => Some(format!(
                    "body {b} is a part of a compound (ChildOf): a jointed body must be a body of \
                 its own"
                )),
                Ok(false) => None,
            });
        let value_problem = joint.is_changed().then(|| joint.problem()).flatten();
        if let Some(problem) = value_problem.or(body_problem) {
            quarantine(&mut commands, e, format!("joint {problem}"));
        }
    }
}

/// Rebuilds [`JointedPairs`] from the joints that do not let their bodies collide.
fn collect_jointed_pairs(joints: Query<&Joint, ActiveJoint>, mut pairs: ResMut<JointedPairs>) {
    let pairs = &mut *pairs;
    pairs.scratch.clear();
    for joint in &joints {
        if let (false, Some(b)) = (joint.collide_connected, joint.body_b_entity()) {
            let a = joint.body_a;
            pairs.scratch.push((a.min(b), a.max(b)));
        }
    }
    if pairs.scratch == pairs.collected {
        return;
    }
    std::mem::swap(&mut pairs.scratch, &mut pairs.collected);
    pairs.pairs.clear();
    pairs.pairs.extend_from_slice(&pairs.collected);
    pairs.pairs.sort_unstable();
    pairs.pairs.dedup();
}

/// Writes each solved joint's [`JointLoad`] and breaks the joints that held more than their
/// thresholds.
fn break_joints(
    solver: Res<SoftStepSolver>,
    mut joints: Query<(&Joint, Option<&mut JointLoad>)>,
    mut broken: MessageWriter<JointBroken>,
    mut commands: Commands,
) {
    for (e, held) in solver.joint_loads() {
        let Ok((joint, load)) = joints.get_mut(e) else {
            continue;
        };
        let now = JointLoad::from(held);
        let (force, torque) = (now.force, now.torque);
        match load {
            Some(mut load) => {
                load.set_if_neq(now);
            }
            None => {
                commands.entity(e).insert(now);
            }
        }
        if force > joint.break_force || torque > joint.break_torque {
            commands.entity(e).insert(JointDisabled);
            broken.write(JointBroken {
                joint: e,
                force,
                torque,
            });
        }
    }
}

//! The joints' side of the solver's gather: which bodies the joints bring into the step, which
//! sleepers they wake, and each [`Joint`] as a core [`JointInput`] between solver slots.

use super::{BodySlots, Mover, MoverFilter};
use crate::components::*;
use crate::dynamics::solver::{JointFrame, JointInput};
use crate::plugins::joints::ActiveJoint;
use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemParam;
use glam::Vec3;

/// What the solver reads of the joints.
#[derive(SystemParam)]
pub(crate) struct JointParams<'w, 's> {
    joints: Query<'w, 's, (Entity, &'static Joint), ActiveJoint>,
    quarantined: Query<'w, 's, (), With<Quarantined>>,
}

impl JointParams<'_, '_> {
    /// Whether any joint is to be solved.
    pub(crate) fn any(&self) -> bool {
        !self.joints.is_empty()
    }

    /// Adds the joints' bodies that the indexed `slots` lack (a quarantined body is left out:
    /// its joints are skipped), then sorts them in and indexes again. Most jointed bodies are
    /// already there (the awake movers): a net of 10,000 balls sorted its 50,000 entries every
    /// step when each joint pushed both of its bodies.
    pub(crate) fn add_bodies(&self, slots: &mut BodySlots) {
        let known = slots.len();
        for (_, joint) in &self.joints {
            for e in [Some(joint.body_a), joint.body_b_entity()]
                .into_iter()
                .flatten()
            {
                // A body pushed here may answer as present: it is, and is not pushed twice.
                if slots.slot(e).is_none() && !self.quarantined.contains(e) {
                    slots.entities_mut().push(e);
                }
            }
        }
        if slots.len() > known {
            let entities = slots.entities_mut();
            entities.sort_unstable();
            entities.dedup();
            slots.index();
        }
    }

    /// Whether a joint names the world (it then needs the world's slot).
    pub(crate) fn any_to_world(&self) -> bool {
        self.joints.iter().any(|(_, j)| j.body_b == JointEnd::World)
    }

    /// Pushes to `waking` each sleeping body jointed to an awake dynamic one (jointed bodies
    /// sleep together; a joint made between an awake and a sleeping body wakes the sleeper).
    pub(crate) fn wake_partners(
        &self,
        movers: &Query<Mover, MoverFilter>,
        waking: &mut Vec<Entity>,
    ) {
        let state = |e: Entity| movers.get(e).ok().map(|m| (m.10, m.5.inverse() > 0.0));
        for (_, joint) in &self.joints {
            let Some(b) = joint.body_b_entity() else {
                continue;
            };
            let a = joint.body_a;
            match (state(a), state(b)) {
                (Some((true, _)), Some((false, true))) => waking.push(a),
                (Some((false, true)), Some((true, _))) => waking.push(b),
                _ => {}
            }
        }
    }

    /// The joints between solver slots: `slots` are indexed, `local_centers[slot]` is each
    /// slot's centre of mass in its body frame (anchors are given from the origin, the solver
    /// takes them from the centre of mass), `world` the world's slot. A joint whose body has
    /// no slot (quarantined, gone) is skipped.
    pub(crate) fn gather(
        &self,
        slots: &BodySlots,
        local_centers: &[Vec3],
        world: Option<u32>,
        out: &mut Vec<JointInput>,
    ) {
        out.clear();
        let slot = |e: Entity| slots.slot(e).map(|s| s as u32);
        for (e, joint) in &self.joints {
            let Some(a) = slot(joint.body_a) else {
                continue;
            };
            let b = match joint.body_b {
                JointEnd::Body(b) => slot(b),
                JointEnd::World => world,
            };
            let Some(b) = b else {
                continue;
            };
            let center = |s: u32| local_centers.get(s as usize).copied().unwrap_or(Vec3::ZERO);
            out.push(JointInput {
                a,
                b,
                frame_a: JointFrame {
                    anchor: joint.anchor_a - center(a),
                    basis: joint.basis_a,
                },
                frame_b: JointFrame {
                    anchor: joint.anchor_b - center(b),
                    basis: joint.basis_b,
                },
                kind: joint.kind,
                key: e.to_bits(),
            });
        }
        // In entity order, not the archetypes' (the sweep's order is part of the result).
        out.sort_unstable_by_key(|j| j.key);
    }
}

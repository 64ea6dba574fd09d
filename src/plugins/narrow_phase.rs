//! The NarrowPhase stage: exact shape tests on the broad phase's candidates.

use crate::components::*;
use crate::geometry::ContactManifold;
use crate::geometry::contacts::contact;
use crate::plugins::broad_phase::BroadPhasePairs;
use crate::schedule::{SubstepSchedule, SubstepSet};
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;

/// Turns candidate pairs into contacts.
#[derive(Debug, Clone, Default)]
pub struct NarrowPhasePlugin;

/// A contact between two entities; the manifold's normal points from `a` to `b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPair {
    /// First body (a moving one).
    pub a: Entity,
    /// Second body.
    pub b: Entity,
    /// Where and how deep they touch.
    pub manifold: ContactManifold,
}

/// The contacts of this substep, in the broad phase's pair order.
#[derive(Resource, Debug, Default, Clone)]
pub struct Contacts {
    /// The touching pairs.
    pub pairs: Vec<ContactPair>,
}

impl Plugin for NarrowPhasePlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<Contacts>().add_systems(
            SubstepSchedule,
            compute_contacts
                .run_if(any_with_component::<Collider>)
                .in_set(SubstepSet::NarrowPhase),
        );
    }
}

fn compute_contacts(
    pairs: Res<BroadPhasePairs>,
    colliders: Query<(&Collider, &Position, &Rotation)>,
    mut contacts: ResMut<Contacts>,
    mut stats: ResMut<PhysicsStats>,
) {
    stats.time(Stage::NarrowPhase, "narrow_phase", || {
        contacts.pairs.clear();
        for &(a, b) in &pairs.pairs {
            let (Ok((ca, pa, ra)), Ok((cb, pb, rb))) = (colliders.get(a), colliders.get(b)) else {
                continue;
            };
            let m = contact(
                &ca.shape,
                &pose(pa, Some(ra)),
                &cb.shape,
                &pose(pb, Some(rb)),
            );
            if let Some(manifold) = m {
                contacts.pairs.push(ContactPair { a, b, manifold });
            }
        }
    });
    let n = contacts.pairs.len();
    stats.set_counter("narrow_phase/contacts", n as f64);
}

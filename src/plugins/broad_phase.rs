//! The BroadPhase stage: refits the world-space [`BoundingVolume`] of moved colliders and lists
//! the candidate pairs whose volumes overlap.

use crate::bounding::Aabb;
use crate::components::*;
use crate::plugins::validation::quarantine;
use crate::schedule::{SubstepSchedule, SubstepSet};
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use std::time::Instant;

/// Keeps bounding volumes fresh and finds candidate pairs.
#[derive(Debug, Clone, Default)]
pub struct BroadPhasePlugin;

/// Candidate pairs of this substep; the first entity of a pair is always a moving body.
#[derive(Resource, Debug, Default, Clone)]
pub struct BroadPhasePairs {
    /// The pairs, in a deterministic order.
    pub pairs: Vec<(Entity, Entity)>,
}

impl Plugin for BroadPhasePlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<BroadPhasePairs>().add_systems(
            SubstepSchedule,
            (refit_bounding_volumes, find_candidate_pairs)
                .chain()
                .run_if(any_with_component::<Collider>)
                .in_set(SubstepSet::BroadPhase),
        );
    }
}

type Moved = (
    Without<Quarantined>,
    Or<(Changed<Position>, Changed<Rotation>, Changed<Collider>)>,
);

/// Recomputes the world AABB of colliders whose pose or shape changed; a non-finite result
/// (a bounded shape at an overflowing pose) quarantines the body.
fn refit_bounding_volumes(
    mut colliders: Query<(Entity, &Collider, &Position, &Rotation, &mut BoundingVolume), Moved>,
    mut stats: ResMut<PhysicsStats>,
    mut commands: Commands,
) {
    let start = Instant::now();
    let mut refits = 0u32;
    for (entity, collider, p, r, mut bv) in &mut colliders {
        let aabb = collider.shape.world_aabb(&pose(p, Some(r)));
        if !collider.shape.is_unbounded() && !aabb.is_finite() {
            quarantine(
                &mut commands,
                entity,
                format!("bounding volume is not finite: {aabb:?}"),
            );
            continue;
        }
        bv.set_if_neq(BoundingVolume(aabb));
        refits += 1;
    }
    stats.set_counter("broad_phase/refits", refits as f64);
    stats.add_time(Stage::BroadPhase, start.elapsed());
}

/// All moving–moving and moving–static pairs whose AABBs overlap (brute force, O(n²)).
type ColliderBox<'a> = (Entity, &'a BoundingVolume, Has<Velocity>, Has<Static>);

fn find_candidate_pairs(
    colliders: Query<ColliderBox, (With<Collider>, Without<Quarantined>)>,
    mut out: ResMut<BroadPhasePairs>,
    mut stats: ResMut<PhysicsStats>,
) {
    let start = Instant::now();
    let mut moving: Vec<(Entity, Aabb)> = Vec::new();
    let mut fixed: Vec<(Entity, Aabb)> = Vec::new();
    for (e, bv, has_velocity, is_static) in &colliders {
        if has_velocity && !is_static {
            moving.push((e, bv.0));
        } else {
            fixed.push((e, bv.0));
        }
    }
    out.pairs.clear();
    for (i, (a, box_a)) in moving.iter().enumerate() {
        for (b, box_b) in moving[i + 1..].iter().chain(fixed.iter()) {
            if box_a.intersects(box_b) {
                out.pairs.push((*a, *b));
            }
        }
    }
    stats.set_counter("broad_phase/pairs", out.pairs.len() as f64);
    stats.add_time(Stage::BroadPhase, start.elapsed());
    stats.count_run("broad_phase");
}

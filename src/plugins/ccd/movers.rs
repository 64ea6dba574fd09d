//! Continuous collision between a fast body and another moving body (or a sleeping one).
//!
//! The speculative contacts catch two moving bodies closing by up to their sizes in a step;
//! past that (two 10 cm balls meeting head on at 10 m/s each, a bullet and a dynamic plank)
//! they pass through each other, as the static sweep never looks at moving bodies. Here each
//! fast body of the substep (those [`super::record_sweep_starts`] kept that move more than a
//! quarter of their radius in it) is swept against the moving and sleeping bodies its swept box
//! meets ([`pairs_with_a_fast_body`]) in their
//! *relative* motion: the other body held at its start pose, the fast one's sphere moving by the
//! difference of the two displacements, refined to its own convex parts as against scenery.
//!
//! At the first impact the fast body is clamped there (rapier's CCD "motion clamping"), its
//! velocity left as it is: the two now touch, and the next step's contact, found by the narrow
//! phase, solves the collision with the pair's masses, restitution and friction. A fast body
//! that hits a slow one rides on with it for the rest of the substep (kept touching it, not
//! left behind where it was hit); two fast bodies that hit each other both stop at the
//! impact. What this leaves out: the other body's turning during the substep (it is swept at
//! its end orientation), and what the fast body meets after a bounce off scenery in the same
//! substep (the discrete step's).
//!
//! A substep with no fast body costs nothing here; otherwise one pass over the moving roots
//! and a sort of those whose boxes meet the swept ones.

use super::parts::{LayeredParts, NodePose, meeting_parts, push_children};
use super::{AnyMovingRoot, Mover, Obstacle, SweepStart, centred_sphere, moves_into};
use crate::bounding::Aabb;
use crate::bvh::QueryScratch;
use crate::ccd::{
    InitialOverlap, MoverPairScratch, SphereSweep, Toi, depth_at_start, pairs_with_a_fast_body,
    toi_parts_from, toi_sphere_shape,
};
use crate::components::*;
use crate::geometry::Isometry;
use crate::geometry::contacts::ContactScratch;
use crate::plugins::joints::JointedPairs;
use crate::plugins::soft_step::SoftStepSolver;
use crate::settings::PhysicsTimestep;
use bevy_ecs::prelude::*;
use glam::Vec3;

/// How deep (a share of its sweep's radius) a fast body may start inside a moving one and still
/// be stopped there when it moves deeper: a bullet clamped at a plank and pushed a hair into it
/// is, a body spawned inside another is not.
const DEEP_START: f32 = 0.1;

/// Most moving bodies one fast body is swept against: one whose swept box meets more is in a
/// heap (a thousand balls spawned on one point), where every pair is a contact already and
/// sweeping each would cost seconds a step; it is left to the discrete step.
const MAX_CANDIDATES: usize = 256;

/// A moving root as the sweeps see it in this substep.
#[derive(Clone, Copy, Debug)]
struct Other {
    body: Entity,
    /// Its root pose at the substep's start: where it ends, moved back by its displacement.
    start: Isometry,
    /// How far it moves in the substep.
    displacement: Vec3,
}

/// The moving bodies of the substep and which fast body may meet which, rebuilt each substep
/// that has a fast body.
#[derive(Resource, Default)]
pub(super) struct MoverTable {
    /// Index-aligned with the swept boxes: the fast bodies first, in the order of their sweep
    /// starts (as many as `fast_bodies`), then the other moving roots.
    others: Vec<Other>,
    boxes: Vec<Aabb>,
    pairs: Vec<[u32; 2]>,
    /// `(fast body, other)` in both directions where both are fast, sorted.
    candidates: Vec<(u32, u32)>,
    pair_scratch: MoverPairScratch,
    /// Each sweep start's place among the fast bodies (`u32::MAX`: not one of them).
    slot_of_start: Vec<u32>,
    /// The fast bodies, sorted (to leave them out of the others).
    fast_bodies: Vec<Entity>,
}

/// A fast body joins the sweeps against moving bodies when it moves more than this share of
/// its sweep's radius in the substep. Two bodies each moving less cannot pass through each other
/// within one (their boxes, grown by their motion over the step, are paired by the broad phase
/// and their speculative contacts look that far ahead); a body marked [`Ccd`] and resting on a
/// pile is then no reason to gather every moving body.
const MOVER_SWEEP_SHARE: f32 = 0.25;

/// Fills the [`MoverTable`] for this substep's sweep starts (leaves it empty when none of them
/// moves fast enough to need it).
pub(super) fn gather_movers(
    bodies: Query<(Mover, Has<Sleeping>), AnyMovingRoot>,
    starts: Res<super::CcdScratch>,
    timestep: Res<PhysicsTimestep>,
    solved: Option<Res<SoftStepSolver>>,
    mut table: ResMut<MoverTable>,
) {
    let t = &mut *table;
    t.others.clear();
    t.boxes.clear();
    t.candidates.clear();
    t.slot_of_start.clear();
    t.slot_of_start.resize(starts.starts.len(), u32::MAX);
    t.fast_bodies.clear();
    // The fast bodies first: those of the sweep starts that move far enough in the substep.
    for (i, start) in starts.starts.iter().enumerate() {
        let Ok(((_, (p, r, _, _), ..), _)) = bodies.get(start.body) else {
            continue;
        };
        let rotation = Rotation::of(r);
        let center = p.0 + rotation * start.local_center;
        let displacement = center - start.from;
        let far = displacement.length() > MOVER_SWEEP_SHARE * start.radius;
        if far && displacement.is_finite() {
            t.slot_of_start[i] = t.others.len() as u32;
            t.fast_bodies.push(start.body);
            t.others.push(Other {
                body: start.body,
                start: Isometry::new(p.0 - displacement, rotation),
                displacement,
            });
            t.boxes
                .push(Aabb::from_points([start.from, center]).expanded(start.radius));
        }
    }
    let fast = t.others.len();
    if fast == 0 {
        return;
    }
    let dt = timestep.substep_dt();
    t.fast_bodies.sort_unstable();
    let reach = t.boxes.iter().fold(Aabb::EMPTY, |union, b| union.union(b));
    for ((body, (p, r, inertia, _), v, bv, collider, compound, _), asleep) in &bodies {
        let rotation = Rotation::of(r);
        let Some((center, radius, _)) =
            centred_sphere((p.0, rotation, inertia), bv, collider, compound)
        else {
            continue;
        };
        // A sleeper is held still; the others moved as the rigid-body solver moved them (a
        // ball struck in the step moved at half the speed the bounce then gave it: taken from
        // its final velocity, it was put behind the ball that struck it, which then passed
        // through it), or, after the lecture's response, by their last velocity.
        let solved = solved.as_ref().and_then(|s| s.step_displacement(body));
        let displacement = if asleep {
            Vec3::ZERO
        } else {
            solved.unwrap_or(v.0 * dt)
        };
        let swept = Aabb::from_points([center - displacement, center]).expanded(radius);
        // Most bodies are far from every fast one (a box with a NaN meets nothing either).
        if !swept.intersects(&reach) || t.fast_bodies.binary_search(&body).is_ok() {
            continue;
        }
        t.others.push(Other {
            body,
            start: Isometry::new(p.0 - displacement, rotation),
            displacement,
        });
        t.boxes.push(swept);
    }
    pairs_with_a_fast_body(&t.boxes, fast, &mut t.pair_scratch, &mut t.pairs);
    for &[i, j] in &t.pairs {
        // `i < j`, and a pair holds a fast body, so `i` is one.
        t.candidates.push((i, j));
        if (j as usize) < fast {
            t.candidates.push((j, i));
        }
    }
    t.candidates.sort_unstable();
}

/// The colliders a sweep may meet, and the local poses of compound parts.
type Obstacles<'w, 's, 'a> = Query<'w, 's, Obstacle<'a>, Without<Quarantined>>;
type Locals<'w, 's, 'a> = Query<'w, 's, NodePose<'a>, With<ChildOf>>;

/// The first impact of fast body `start` (its sweep `sweep` over the whole substep) with a moving
/// body: the fast body's place at that impact, the hit (point in the world at the impact), the
/// other root and the collider of it that was hit.
pub(super) struct MoverImpact {
    /// Where the fast body's swept centre ends the substep: at the impact, carried on by a slow
    /// body it hit for the rest of the substep.
    pub center: Vec3,
    /// The hit: the fraction `t` of the substep's motion at the impact, the normal from the
    /// other body towards the fast one, the point in the world at `t`.
    pub hit: Toi,
    pub other: Entity,
    pub collider: Entity,
    /// The speed at which the two approached along the normal.
    pub approach: f32,
}

/// The earliest impact of fast body number `index` (sweep start `start`, its whole substep's
/// `sweep`, its `layers` and convex `parts`) with the moving bodies it may meet, or `None`.
pub(super) fn first_mover_impact(
    index: usize,
    (start, sweep): (&SweepStart, &SphereSweep),
    (layers, parts): (CollisionLayers, LayeredParts),
    (table, jointed, dt): (&MoverTable, Option<&JointedPairs>, f32),
    (obstacles, locals): (&Obstacles, &Locals),
    stack: &mut Vec<(Entity, Isometry)>,
    (query, contacts): (&mut QueryScratch, &mut ContactScratch),
) -> Option<MoverImpact> {
    let slot = *table.slot_of_start.get(index)?;
    let from = table.candidates.partition_point(|c| c.0 < slot);
    let to = table.candidates.partition_point(|c| c.0 <= slot);
    if to - from > MAX_CANDIDATES {
        return None;
    }
    let mut best: Option<MoverImpact> = None;
    for &(_, j) in &table.candidates[from..to] {
        let other = table.others[j as usize];
        if jointed.is_some_and(|p| p.contains(start.body, other.body)) {
            continue;
        }
        let relative = sweep.displacement() - other.displacement;
        let Ok(relative) = SphereSweep::new(sweep.center(), sweep.radius(), relative) else {
            continue;
        };
        let relative = relative.with_initial_overlap(InitialOverlap::ApproachingOnly);
        stack.clear();
        stack.push((other.body, other.start));
        while let Some((node, pose)) = stack.pop() {
            let Ok((collider, _, _, children, _, node_layers, sensor)) = obstacles.get(node) else {
                continue;
            };
            push_children(children, &pose, locals, stack);
            let Some(c) = collider.filter(|_| !sensor) else {
                continue;
            };
            let Some(meeting) = meeting_parts(parts, layers, &layers_of(node_layers)) else {
                continue;
            };
            let Some(mut hit) = toi_sphere_shape(&relative, &c.shape, &pose, query) else {
                continue;
            };
            if best.as_ref().is_some_and(|b| b.hit.t < hit.t) {
                continue;
            }
            if !meeting.is_empty() {
                match toi_parts_from(&relative, &meeting, hit, (&c.shape, &pose), contacts) {
                    Some(own) => hit = own,
                    None => continue,
                }
            }
            // As against scenery; but a body already deep inside another moving one (spawned
            // there, or pushed) is left to the contact solver to separate: stopping it there
            // kept 1,000 balls spawned on one point from ever flying apart.
            let (into, moving_in) = moves_into(&relative, &hit);
            let real = moving_in
                && (hit.t > 0.0
                    || depth_at_start(&relative, &meeting, (&c.shape, &pose), contacts)
                        <= DEEP_START * relative.radius());
            let earlier = best
                .as_ref()
                .is_none_or(|b| hit.t < b.hit.t || (hit.t == b.hit.t && other.body < b.other));
            if real && earlier {
                // The hit was found in the other body's frame held at its start.
                hit.point += other.displacement * hit.t;
                // A fast body stops at its own impacts: it is never ridden on.
                let fast = (j as usize) < table.fast_bodies.len();
                let ride = if fast {
                    Vec3::ZERO
                } else {
                    other.displacement * (1.0 - hit.t)
                };
                best = Some(MoverImpact {
                    center: sweep.position_at(hit.t) + ride,
                    hit,
                    other: other.body,
                    collider: node,
                    approach: (into / dt).max(0.0),
                });
            }
        }
    }
    best
}

//! Continuous collision in the step: fast bodies stop at thin walls instead of tunnelling.
//!
//! The slides' cure for tunnelling is to split `dt` into substeps (brute force: every body pays).
//! Here only the bodies that need it pay: those marked [`Ccd`], and — when
//! [`CcdSettings::auto_speed_ratio`] is set — those moving more than that many times their own
//! size in one substep. For each, the motion the integrator just produced (its centre of mass,
//! start → end) is swept against the static scenery its swept volume meets ([`crate::ccd`]:
//! exact time of impact of a sphere about the centre of mass holding the body, against spheres,
//! boxes, planes and meshes; for a body of convex colliders, one or the parts of a compound,
//! refined from there to the earliest of the colliders' own first contacts by conservative
//! advancement, [`toi_parts_from`], so a long thin body or a chair is not stopped where its
//! bounding sphere met the wall). The centre of mass, not the origin, because that is what
//! [`Velocity`] moves and what the solver turns the body about: sweeping the origin of a
//! spinning body whose centre is off it (a cone, a compound) and reflecting the velocity there
//! moved its centre of mass up to 1.17 × its speed bound in a step (the fuzz scenes). At the first
//! impact the body is moved there, its velocity is reflected with the pair's restitution, and it
//! spends the rest of the substep from there (up to [`CcdSettings::max_impacts`] impacts). Each
//! impact also becomes a contact of the substep, so collision messages report it.
//!
//! Moving and sleeping bodies are swept against too, in the pair's relative motion, and a fast
//! body that meets one first is clamped at that impact for the next step's contact to solve
//! (`movers.rs`). Sensors neither sweep nor stop a sweep, and colliders whose
//! [`CollisionLayers`] do not interact pass through each other here too, as do bodies a
//! [`Joint`] keeps from colliding. A body already touching a surface
//! at the start of its motion is the contact solver's business, not an impact.

use crate::bvh::QueryScratch;
use crate::ccd::{
    InitialOverlap, MAX_REFINED_TURN, SphereSweep, Toi, toi_parts_from, toi_sphere_shape,
};
use crate::components::*;
use crate::dynamics::response::reflect;
use crate::geometry::contacts::ContactScratch;
use crate::geometry::{ContactManifold, Isometry};
use crate::plugins::broad_phase::BroadPhaseIndex;
use crate::plugins::integration::IntegrateBodies;
use crate::plugins::joints::JointedPairs;
use crate::plugins::narrow_phase::{ComputeContacts, ContactPair, Contacts};
use crate::plugins::required_resources::RequireResource;
use crate::plugins::response::ReportCollisions;
use crate::plugins::soft_step::{SolveBodies, legacy_solver};
use crate::schedule::{SubstepSchedule, SubstepSet};
use crate::settings::{ContactSettings, PhysicsTimestep};
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use movers::{MoverImpact, MoverTable, first_mover_impact, gather_movers};
use parts::{LayeredParts, NodePose, meeting_parts, parts_on_sweep};
use std::time::Instant;

mod movers;
mod parts;

/// Sweeps fast bodies against static scenery each substep.
#[derive(Debug, Clone, Default)]
pub struct CcdPlugin;

/// When continuous collision applies.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct CcdSettings {
    /// Sweep any moving body whose motion in one substep exceeds this many times its bounding
    /// radius, marked [`Ccd`] or not (`None`: only marked bodies). Default 1: a body that could
    /// pass through an obstacle as thick as itself in one substep is swept.
    pub auto_speed_ratio: Option<f32>,
    /// Most impacts handled for one body in one substep (a ball in a narrow corridor).
    pub max_impacts: u32,
}

impl Default for CcdSettings {
    fn default() -> Self {
        Self {
            auto_speed_ratio: Some(1.0),
            max_impacts: 4,
        }
    }
}

/// The impacts found by the sweeps of the current substep (also added to [`Contacts`]).
#[derive(Resource, Debug, Default, Clone)]
pub struct CcdImpacts {
    /// Body `a` hit static collider `collider_b` of body `b`; depth 0, normal from `a` to `b`.
    pub contacts: Vec<ContactPair>,
}

impl Plugin for CcdPlugin {
    fn build(&self, app: &mut App) {
        app.init_required::<CcdSettings>()
            .init_required::<CcdImpacts>()
            .init_required::<CcdScratch>()
            .init_required::<MoverTable>()
            .add_systems(
                SubstepSchedule,
                (
                    (
                        record_sweep_starts.before(IntegrateBodies),
                        (gather_movers, sweep_fast_bodies)
                            .chain()
                            .after(IntegrateBodies)
                            .run_if(legacy_solver),
                    )
                        .run_if(any_with_component::<Velocity>)
                        .in_set(SubstepSet::Integrate),
                    add_impacts_to_contacts
                        .after(ComputeContacts)
                        .run_if(legacy_solver)
                        .in_set(SubstepSet::NarrowPhase),
                    // With the rigid-body solver the motion is the solver's: sweep it after
                    // the solve, and report the impacts with the step's collisions.
                    (gather_movers, sweep_fast_bodies, add_impacts_to_contacts)
                        .chain()
                        .run_if(not(legacy_solver))
                        .run_if(any_with_component::<Velocity>)
                        .after(SolveBodies)
                        .before(ReportCollisions)
                        .in_set(SubstepSet::Response),
                ),
            );
    }
}

/// A body to sweep: where its centre of mass started the substep, the radius of the sphere
/// about it that is swept, and the centre's place in the body's frame.
#[derive(Clone, Copy, Debug)]
struct SweepStart {
    body: Entity,
    from: Vec3,
    radius: f32,
    local_center: Vec3,
    /// The body's orientation at the substep's start.
    rotation: Quat,
    /// How far it may turn in the substep (rad, at its angular velocity then).
    turn: f32,
}

#[derive(Resource, Default)]
struct CcdScratch {
    starts: Vec<SweepStart>,
    candidates: Vec<Entity>,
    stack: Vec<Entity>,
    /// The nodes of a compound still to visit, with their poses in its frame.
    part_stack: Vec<(Entity, Isometry)>,
    query: QueryScratch,
    contacts: ContactScratch,
}

type Mover<'a> = (
    Entity,
    (
        &'a Position,
        Option<&'a Rotation>,
        Option<&'a Inertia>,
        Option<&'a AngularVelocity>,
    ),
    &'a Velocity,
    &'a BoundingVolume,
    Option<&'a Collider>,
    Has<Children>,
    Has<Ccd>,
);
/// A root that may move: asleep or not ([`movers`] meets sleepers too).
type AnyMovingRoot = (
    Without<Static>,
    Without<Sensor>,
    Without<Quarantined>,
    Without<ChildOf>,
);
/// A root that moves in this substep.
type MovingRoot = (AnyMovingRoot, Without<Sleeping>);

/// Radius of the sphere swept for a body at `p`: its collider's bounding radius (exact for a
/// ball); for a compound body, the sphere about `p` holding its whole volume (parts included).
/// `None` for bodies with nothing to sweep (no collider, or an unbounded one).
fn sweep_radius(
    p: Vec3,
    bv: &BoundingVolume,
    collider: Option<&Collider>,
    compound: bool,
) -> Option<f32> {
    if compound {
        let b = bv.0;
        return (b.is_valid() && b.is_finite())
            .then(|| (b.center() - p).length() + b.half_extents().length());
    }
    collider
        .map(|c| c.shape.bounding_radius())
        .filter(|r| r.is_finite())
}

/// The sphere swept for a body at `p` turned by `rotation`: about its centre of mass, holding
/// the whole body (the [`sweep_radius`] sphere about `p`, grown by the centre's offset). Its
/// centre, its radius and the body's local centre of mass; `None` as for [`sweep_radius`].
fn centred_sphere(
    (p, rotation, inertia): (Vec3, Quat, Option<&Inertia>),
    bv: &BoundingVolume,
    collider: Option<&Collider>,
    compound: bool,
) -> Option<(Vec3, f32, Vec3)> {
    let radius = sweep_radius(p, bv, collider, compound)?;
    let local_center = inertia.map_or(Vec3::ZERO, |i| i.local_center_of_mass);
    // Most bodies hold their centre of mass at their origin: no turn to apply (this runs for
    // every moving body of every substep with a fast one).
    let offset = if local_center == Vec3::ZERO {
        Vec3::ZERO
    } else {
        rotation * local_center
    };
    Some((p + offset, radius + offset.length(), local_center))
}

fn record_sweep_starts(
    bodies: Query<(Mover, Option<&ComputedMass>), MovingRoot>,
    settings: Res<CcdSettings>,
    timestep: Res<PhysicsTimestep>,
    mut scratch: ResMut<CcdScratch>,
) {
    scratch.starts.clear();
    let dt = timestep.substep_dt();
    for ((body, (p, r, inertia, w), v, bv, collider, compound, marked), mass) in &bodies {
        // A kinematic body follows the game's velocity whatever it meets (rapier's CCD leaves
        // kinematic bodies alone too): it is never swept, only met. Until 2026-12-05 one fast
        // enough bounced off static walls, its velocity reflected.
        if mass.is_some_and(|m| m.inverse() == 0.0) {
            continue;
        }
        let rotation = Rotation::of(r);
        let Some((from, radius, local_center)) =
            centred_sphere((p.0, rotation, inertia), bv, collider, compound)
        else {
            continue;
        };
        let turn = w.map_or(0.0, |w| w.0.length() * dt);
        let fast = settings.auto_speed_ratio.is_some_and(|k| {
            let thin = collider.filter(|_| !compound);
            v.0.length() * dt > k * radius || turns_past_its_thickness(turn, radius, thin, k)
        });
        if marked || fast {
            scratch.starts.push(SweepStart {
                body,
                from,
                radius,
                local_center,
                rotation,
                turn,
            });
        }
    }
}

/// Whether a body turning by `turn` (rad) in a substep moves the part of it outside its
/// inner ball (`Shape::inner_radius`, its thickness) by more than `k` times that thickness:
/// a plank, a bat or a thin capsule spinning fast, whatever its speed. The speculative
/// contacts, found once a step at its start pose, follow each point in a straight line and
/// miss what a half-turn brings round: a capsule 1 cm thick at 5 m/s and 150 rad/s passed a
/// 1 cm wall in 3 of 40 throws and came out faster (a user-style probe). A ball turns
/// nothing, and a body with no known inside (a mesh) or a compound is left to its speed.
fn turns_past_its_thickness(turn: f32, radius: f32, collider: Option<&Collider>, k: f32) -> bool {
    let Some(c) = collider else {
        return false;
    };
    let core = c.shape.inner_radius();
    core > 0.0 && turn * (radius - core) > k * core
}

type Obstacle<'a> = (
    Option<&'a Collider>,
    &'a GlobalPose,
    &'a BoundingVolume,
    Option<&'a Children>,
    Option<&'a Restitution>,
    Option<&'a CollisionLayers>,
    Has<Sensor>,
);

type Swept<'a> = (
    &'a mut Position,
    Option<&'a Rotation>,
    &'a mut Velocity,
    Option<&'a Restitution>,
    Option<&'a LockedAxes>,
);

/// Sweeps each recorded body from its start to where the integrator put it.
#[allow(clippy::too_many_arguments)]
fn sweep_fast_bodies(
    mut bodies: Query<Swept, MovingRoot>,
    obstacles: Query<Obstacle, Without<Quarantined>>,
    locals: Query<NodePose, With<ChildOf>>,
    index: Option<ResMut<BroadPhaseIndex>>,
    settings: Res<CcdSettings>,
    contact_settings: Res<ContactSettings>,
    timestep: Res<PhysicsTimestep>,
    mut scratch: ResMut<CcdScratch>,
    mut impacts: ResMut<CcdImpacts>,
    mut stats: ResMut<PhysicsStats>,
    jointed: Option<Res<JointedPairs>>,
    movers: Res<MoverTable>,
) {
    impacts.contacts.clear();
    let jointed = jointed.as_deref().filter(|j| !j.is_empty());
    // Without a broad phase there is no indexed scenery to sweep against (moving bodies still).
    let mut index = index;
    if scratch.starts.is_empty() {
        return;
    }
    let start = Instant::now();
    let dt = timestep.substep_dt();
    let s = &mut *scratch;
    let (mut parts, mut part_layers) = (Vec::new(), Vec::new());
    let mut mover_impacts = 0u32;
    for i in 0..s.starts.len() {
        let SweepStart {
            body,
            from,
            radius,
            local_center,
            rotation,
            turn,
        } = s.starts[i];
        let Ok((mut p, r, mut v, e_body, locked)) = bodies.get_mut(body) else {
            continue;
        };
        // Where the integrator put the centre of mass, the body turned as it ends the substep.
        let now = Rotation::of(r);
        let offset = now * local_center;
        let to = p.0 + offset;
        let e_body = e_body.map_or(contact_settings.default_restitution, |r| r.0);
        let own = obstacles.get(body).ok();
        let layers = layers_of(own.and_then(|o| o.5));
        if !(to - from).is_finite() {
            // The integrator overflowed: leave the body where it is, for the refit to quarantine.
            continue;
        }
        // The sphere's impacts are refined to the body's own convex parts (not for a body
        // spinning so fast that the slerp between its two orientations may not be the way it
        // turned).
        let rotations = (turn <= MAX_REFINED_TURN).then_some([rotation, now]);
        parts_on_sweep(
            body,
            (rotations, local_center),
            &obstacles,
            &locals,
            &mut s.part_stack,
            (&mut parts, &mut part_layers),
        );
        let free = LockedAxes::of(locked).free_translation_axes();
        let (mut at, mut velocity, mut motion) = (from, v.0, to - from);
        let mut impacted = false;
        let mut mover = SphereSweep::new(from, radius, motion)
            .ok()
            .and_then(|sweep| {
                first_mover_impact(
                    i,
                    (&s.starts[i], &sweep),
                    (layers, (&parts, &part_layers)),
                    (&movers, jointed, dt),
                    (&obstacles, &locals),
                    &mut s.part_stack,
                    (&mut s.query, &mut s.contacts),
                )
            });
        // The share of the step still to move: each impact uses up its sweep's `t` of what was
        // left (a second impact at t = 0 is not handed a fresh step).
        let mut remaining = 1.0f32;
        for _ in 0..settings.max_impacts {
            let Ok(sweep) = SphereSweep::new(at, radius, motion) else {
                at += motion;
                break;
            };
            let sweep = sweep.with_initial_overlap(InitialOverlap::ApproachingOnly);
            let found = index.as_deref_mut().and_then(|index| {
                let meets = (body, layers, jointed, (&parts[..], &part_layers[..]));
                first_impact(&sweep, meets, &obstacles, index, s)
            });
            // A moving body met before any scenery stops the sweep there (first pass only:
            // what the body meets after a bounce is the discrete step's).
            let earlier = |m: &MoverImpact| found.as_ref().is_none_or(|(h, ..)| m.hit.t <= h.t);
            if let Some(m) = mover.take().filter(earlier) {
                at = from + (m.center - from) * free;
                impacted = true;
                mover_impacts += 1;
                impacts.contacts.push(ContactPair {
                    a: body,
                    b: m.other,
                    collider_a: body,
                    collider_b: m.collider,
                    manifold: ContactManifold::single(-m.hit.normal, m.hit.point, 0.0),
                    normal_impulse: 0.0,
                    impact_speed: m.approach,
                    rounding: [0.0; 2],
                });
                break;
            }
            let Some((hit, root, leaf, e_obstacle)) = found else {
                at += motion;
                motion = Vec3::ZERO;
                break;
            };
            let e = 0.5 * (e_body + e_obstacle.unwrap_or(contact_settings.default_restitution));
            let approach = -velocity.dot(hit.normal);
            // As in the contact solver: slow approaches (a body resting or sliding on its
            // support, which gravity pushes in every substep) stop without a bounce.
            let e = if approach < contact_settings.solver.restitution_threshold {
                0.0
            } else {
                e
            };
            at = sweep.position_at(hit.t);
            for part in &mut parts {
                // The next sweep turns on from where this one met the obstacle.
                part.rotations[0] = part.rotation_at(hit.t);
            }
            impacted = true;
            // A bounce off a tilted surface must not push a body along a locked axis.
            velocity = reflect(velocity, hit.normal, e) * free;
            remaining *= 1.0 - hit.t;
            motion = velocity * dt * remaining;
            impacts.contacts.push(ContactPair {
                a: body,
                b: root,
                collider_a: body,
                collider_b: leaf,
                manifold: ContactManifold::single(-hit.normal, hit.point, 0.0),
                normal_impulse: 0.0,
                impact_speed: approach.max(0.0),
                rounding: [0.0; 2],
            });
        }
        // Impacts left over (max_impacts reached): stay at the last impact point. Without an
        // impact the body stays exactly where the integrator put it (`at − offset` would round).
        let _ = motion;
        if impacted {
            p.set_if_neq(Position(at - offset));
            v.set_if_neq(Velocity(velocity));
        }
    }
    stats.add_counter("ccd/sweeps", s.starts.len() as f64);
    stats.add_counter("ccd/mover_impacts", mover_impacts as f64);
    stats.add_counter("ccd/impacts", impacts.contacts.len() as f64);
    stats.add_time(Stage::Integrate, start.elapsed());
    stats.count_run("ccd");
}

/// Motion into a surface already touched at the start of a sweep, as a fraction of the radius,
/// below which it is rounding (a body sliding along its support), not an impact.
const TOUCHING_TOLERANCE: f32 = 1e-4;

/// How far `sweep` moves into the surface of `hit` (along its normal), and whether that makes
/// the hit an impact: any hit after the start does; a contact already there at t = 0 counts
/// when the motion goes into it by more than rounding (left to the solver, which sees only the
/// end of the substep, a body touching a thin wall would pass it). Motion along the surface is
/// no impact.
fn moves_into(sweep: &SphereSweep, hit: &Toi) -> (f32, bool) {
    let into = -sweep.displacement().dot(hit.normal);
    (
        into,
        hit.t > 0.0 || into > TOUCHING_TOLERANCE * sweep.radius(),
    )
}

/// The earliest impact of `sweep` (`body`, with `layers`) with the static scenery its swept
/// volume meets, its layers interact with and no joint keeps it from colliding with: the hit,
/// the obstacle's root, the collider hit, and that collider's restitution. With `parts` (and
/// their layers), each sphere impact is refined to the earliest of the parts' own
/// ([`toi_parts_from`]), among the parts whose own layers interact with the obstacle's (as the
/// narrow phase pairs parts), and one they all miss is none.
fn first_impact(
    sweep: &SphereSweep,
    (body, layers, jointed, (parts, part_layers)): (
        Entity,
        CollisionLayers,
        Option<&JointedPairs>,
        LayeredParts,
    ),
    obstacles: &Query<Obstacle, Without<Quarantined>>,
    index: &mut BroadPhaseIndex,
    s: &mut CcdScratch,
) -> Option<(Toi, Entity, Entity, Option<f32>)> {
    let swept = sweep.swept_aabb();
    s.candidates.clear();
    index.statics_touching(&swept, &mut s.candidates);
    let mut best: Option<(Toi, Entity, Entity, Option<f32>)> = None;
    for &root in &s.candidates {
        if jointed.is_some_and(|j| j.contains(body, root)) {
            continue;
        }
        s.stack.clear();
        s.stack.push(root);
        while let Some(node) = s.stack.pop() {
            let Ok((collider, global, bv, children, e, node_layers, sensor)) = obstacles.get(node)
            else {
                continue;
            };
            if !bv.0.intersects(&swept) {
                continue;
            }
            s.stack.extend(children.into_iter().flat_map(|c| c.iter()));
            let Some(c) = collider else {
                continue;
            };
            let obstacle_layers = layers_of(node_layers);
            let meeting = meeting_parts((parts, part_layers), layers, &obstacle_layers);
            if sensor || meeting.is_none() {
                continue;
            }
            let Some(mut hit) = toi_sphere_shape(sweep, &c.shape, &global.0, &mut s.query) else {
                continue;
            };
            if let Some(meeting) = meeting.filter(|m| !m.is_empty()) {
                // The parts' impact is never earlier than their sphere's: past the best so far,
                // it cannot win.
                if best.as_ref().is_some_and(|(b, ..)| b.t <= hit.t) {
                    continue;
                }
                let obstacle = (&c.shape, &global.0);
                match toi_parts_from(sweep, &meeting, hit, obstacle, &mut s.contacts) {
                    Some(own) => hit = own,
                    None => continue,
                }
            }
            let (_, real) = moves_into(sweep, &hit);
            let earlier = best.as_ref().is_none_or(|(b, ..)| hit.t < b.t);
            if real && earlier {
                best = Some((hit, root, node, e.map(|r| r.0)));
            }
        }
    }
    best
}

/// The substep's impacts join the narrow phase's contacts (once per pair), so the response and
/// the collision messages see them; being separating already, they get no further impulse.
/// Sorted keys keep this linear-logarithmic: a pile of marked bodies resting on the ground
/// makes as many impacts as contacts.
fn add_impacts_to_contacts(
    impacts: Res<CcdImpacts>,
    mut contacts: ResMut<Contacts>,
    mut known: Local<Vec<(Entity, Entity)>>,
) {
    if impacts.contacts.is_empty() {
        return;
    }
    known.clear();
    known.extend(contacts.pairs.iter().map(|c| (c.a, c.b)));
    known.sort_unstable();
    let added_from = contacts.pairs.len();
    for impact in &impacts.contacts {
        // A body's impacts are consecutive: one hitting the same body twice is found among them.
        let repeated = contacts.pairs[added_from..]
            .iter()
            .rev()
            .take_while(|c| c.a == impact.a)
            .any(|c| c.b == impact.b);
        if !repeated && known.binary_search(&(impact.a, impact.b)).is_err() {
            contacts.pairs.push(*impact);
        }
    }
}

//! Static bodies nobody writes to are left out of every change scan.
//!
//! The stages find what game code changed through Bevy's `Changed` filters, which visit every
//! entity a query matches, changed or not: with 100,000 static boxes in a level, ten such scans
//! (pose propagation, volume refit, the broad phase's index, validation, mass properties, the
//! game's `Transform`s) cost 184 instructions per static body per step, 1.3 ms, though nothing
//! had moved. A static root body without parts ([`Static`], not quarantined) gets the crate's
//! [`Settled`] marker at the end of each step, and the change scans leave settled bodies out at
//! the archetype level (`Without<Settled>`), as they leave sleeping ones out. At the start of
//! the next step, before the game's `Transform`s are read, the settled tables are checked the
//! way sleeping ones are ([`super::wake_on_writes`]): by the summary ticks of their columns, one
//! comparison per column of a table nobody wrote to, row by row only where one was written
//! (and always for `Transform`, `ChildOf`, `Children` and `Quarantined`, which have no summary
//! tick). A settled body game code wrote to (moved, turned, reshaped, given a velocity, mass or
//! force, layers, friction or restitution, stripped of its collider) loses the marker, so the scans see its change, and settles
//! again at the end of the step; one that stopped being static loses it for good. Compounds do
//! not settle: a part's change re-fits its root's volume in mid-step, after the check.

use crate::components::*;
use crate::plugins::table_ticks::{dense, mark, written_ticks};
use bevy_ecs::bundle::InsertMode;
use bevy_ecs::change_detection::ContiguousComponentTicksRef;
use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::prelude::*;
use bevy_ecs::query::ContiguousQueryData;
use bevy_ecs::system::entity_command;
use bevy_ecs::world::DeferredWorld;
use bevy_transform::components::Transform;
use std::sync::atomic::{AtomicU64, Ordering};

/// A static body no game code wrote to since the last step's end: left out of the change scans.
#[derive(Component, Clone, Copy, Debug, Default)]
#[component(on_add = note_settling, on_remove = note_settling)]
pub(crate) struct Settled;

/// Names the sets of *still* bodies, the settled statics and the sleeping bodies: a new value
/// for a set whenever a body joins or leaves it ([`Settled`] or [`Sleeping`] added or removed,
/// despawns included), so that a reader keeping something per still body (the spatial
/// queries' still and sleeping groups) knows a set is unchanged without reading it. Values come
/// from one counter for every world, so a resource put back after game code removed it never
/// repeats a value a reader kept.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct StillRevision {
    /// The set of settled statics.
    pub(crate) settled: u64,
    /// The set of sleeping bodies.
    pub(crate) sleeping: u64,
}

impl Default for StillRevision {
    fn default() -> Self {
        Self {
            settled: next_revision(),
            sleeping: next_revision(),
        }
    }
}

fn next_revision() -> u64 {
    NEXT_STILL_REVISION.fetch_add(1, Ordering::Relaxed)
}

static NEXT_STILL_REVISION: AtomicU64 = AtomicU64::new(1);

/// The [`Settled`] marker's hooks: the set of settled bodies changed.
fn note_settling(mut world: DeferredWorld, _: HookContext) {
    if let Some(mut revision) = world.get_resource_mut::<StillRevision>() {
        revision.settled = next_revision();
    }
}

/// The set of sleeping bodies changed (the [`Sleeping`] marker's hooks call it).
pub(crate) fn note_sleeping_change(world: &mut DeferredWorld) {
    if let Some(mut revision) = world.get_resource_mut::<StillRevision>() {
        revision.sleeping = next_revision();
    }
}

/// Change scans leave settled bodies out.
pub(crate) type Unsettled = Without<Settled>;

/// Every component a change scan of the step watches on a static body (read only for whether it
/// was written).
type Watched<'a> = (
    Entity,
    (
        Option<Ref<'a, Position>>,
        Option<Ref<'a, Rotation>>,
        Option<Ref<'a, Velocity>>,
        Option<Ref<'a, AngularVelocity>>,
        Option<Ref<'a, Collider>>,
        Option<Ref<'a, GlobalPose>>,
        Option<Ref<'a, BoundingVolume>>,
        Option<Ref<'a, Transform>>,
    ),
    (
        Option<Ref<'a, Mass>>,
        Option<Ref<'a, Density>>,
        Option<Ref<'a, Inertia>>,
        Option<Ref<'a, Force>>,
        Option<Ref<'a, Torque>>,
        Option<Ref<'a, ForceAtPoint>>,
        Option<Ref<'a, Impulse>>,
        Option<Ref<'a, GravityScale>>,
    ),
    (
        Option<Ref<'a, AngularDrag>>,
        Option<Ref<'a, LinearDrag>>,
        Option<Ref<'a, LockedAxes>>,
        Option<Ref<'a, ChildOf>>,
        Option<Ref<'a, Children>>,
        Option<Ref<'a, Quarantined>>,
        Option<Ref<'a, CollisionLayers>>,
        Option<Ref<'a, Friction>>,
        Option<Ref<'a, Restitution>>,
    ),
);

/// One settled table's data as [`Watched`] yields it.
type WatchedTable<'w, 's> = <Watched<'static> as ContiguousQueryData>::Contiguous<'w, 's>;

/// Buffers of [`unsettle_written`], kept from step to step.
#[derive(Default)]
pub(crate) struct UnsettleScratch {
    rows: Vec<u8>,
    written: Vec<Entity>,
    warned: bool,
}

/// Takes the [`Settled`] marker off the bodies game code wrote to since the last step, and off
/// those no longer static.
pub(crate) fn unsettle_written(
    settled: Query<Watched, With<Settled>>,
    no_longer_static: Query<Entity, (With<Settled>, Without<Static>)>,
    mut lost_collider: RemovedComponents<Collider>,
    mut scratch: Local<UnsettleScratch>,
    mut commands: Commands,
) {
    let s = &mut *scratch;
    s.written.extend(no_longer_static.iter());
    // A removal leaves no tick to find; the refit empties the volume of a body that lost its
    // collider, which the broad phase must see.
    s.written
        .extend(lost_collider.read().filter(|&e| settled.contains(e)));
    // Every watched component is stored in tables, so the query is dense.
    let cannot = "settled static bodies cannot be checked for writes";
    match dense(settled.contiguous_iter(), &mut s.warned, cannot) {
        Some(tables) => {
            for table in tables {
                written_rows(table, &mut s.rows, &mut s.written);
            }
        }
        // Unchecked, every settled body is taken as written: the scans see them all.
        None => s.written.extend(settled.iter().map(|(e, ..)| e)),
    }
    for e in s.written.drain(..) {
        if let Ok(mut entity) = commands.get_entity(e) {
            entity.queue_silenced(entity_command::remove::<Settled>());
        }
    }
}

/// Adds to `written` the entities of one settled table with a watched column written since the
/// last check; reads no row of a table whose columns' summary ticks say none was.
fn written_rows(table: WatchedTable<'_, '_>, rows: &mut Vec<u8>, written: &mut Vec<Entity>) {
    let (entities, (a0, a1, a2, a3, a4, a5, a6, a7), (b0, b1, b2, b3, b4, b5, b6, b7), c) = table;
    let (c0, c1, c2, c3, c4, c5, c6, c7, c8) = c;
    let columns: [Option<ContiguousComponentTicksRef<'_>>; 25] = [
        written_ticks(a0),
        written_ticks(a1),
        written_ticks(a2),
        written_ticks(a3),
        written_ticks(a4),
        written_ticks(a5),
        written_ticks(a6),
        written_ticks(a7),
        written_ticks(b0),
        written_ticks(b1),
        written_ticks(b2),
        written_ticks(b3),
        written_ticks(b4),
        written_ticks(b5),
        written_ticks(b6),
        written_ticks(b7),
        written_ticks(c0),
        written_ticks(c1),
        written_ticks(c2),
        written_ticks(c3),
        written_ticks(c4),
        written_ticks(c5),
        written_ticks(c6),
        written_ticks(c7),
        written_ticks(c8),
    ];
    if columns.iter().all(Option::is_none) {
        return;
    }
    rows.clear();
    rows.resize(entities.len(), 0);
    for ticks in columns.iter().flatten() {
        mark(rows, ticks, 1);
    }
    let touched = rows.iter().zip(entities).filter(|(flag, _)| **flag != 0);
    written.extend(touched.map(|(_, e)| *e));
}

/// Static roots not settled yet, and usable.
/// Compounds do not settle: a part's change re-fits its root's volume in mid-step, after the
/// check, where the broad phase (which leaves settled bodies out) would miss it.
type ToSettle = (
    With<Static>,
    Unsettled,
    Without<ChildOf>,
    Without<Children>,
    Without<Quarantined>,
);

/// Static root bodies that are not settled yet settle at the step's end: the step's scans have
/// seen whatever changed them.
pub(crate) fn settle_statics(unsettled: Query<Entity, ToSettle>, mut commands: Commands) {
    for e in &unsettled {
        commands
            .entity(e)
            .queue_silenced(entity_command::insert(Settled, InsertMode::Replace));
    }
}

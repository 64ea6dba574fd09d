//! Waking sleeping bodies that game code wrote to, at a cost per sleeping *table* rather than
//! per sleeping body.
//!
//! Bevy has no hook on a component's mutation: a write through `Mut` only stamps the row's
//! change tick, so finding the sleepers a game moved, pushed or reshaped means reading ticks.
//! Read body by body (eighteen `Changed` filters), 10,000 sleeping balls cost 57× rapier's
//! whole sleeping step, against the rigid-body issue's target of 10×. Bevy 0.20 can keep a
//! *summary tick* per table column (`#[component(summary_tick)]`, set on every component
//! below): the last time any of its rows was written. Sleeping bodies live in tables of their
//! own (the [`Sleeping`] marker is a table component), so this check iterates the sleeping
//! tables contiguously: a table none of whose columns was written since the check last ran is
//! passed over with one tick comparison per column, and only the ticks of written columns are
//! read row by row. Bevy's own `ChildOf` and `Children` have no summary tick; their ticks are
//! always read (only bodies in a hierarchy have them). Rows moved into a table (a body falling
//! asleep) carry their change ticks with them, so the step after a body falls asleep reads its
//! table once.

use crate::components::*;
use crate::plugins::sleep::Waker;
use crate::plugins::table_ticks::{dense, if_written, mark, written_ticks};
use crate::settings::Gravity;
use bevy_ecs::change_detection::{ContiguousComponentTicksRef, ContiguousRef};
use bevy_ecs::prelude::*;
use glam::Vec3;

/// The columns of a sleeping table the check reads: who, what it slept with, where it is and
/// how it moves, what pushes it, and what it is made of (only written or not).
type SleeperColumns<'a> = (
    (Entity, &'a SleepState),
    (
        Ref<'a, Position>,
        Ref<'a, Rotation>,
        Ref<'a, Velocity>,
        Option<Ref<'a, AngularVelocity>>,
    ),
    (
        Option<Ref<'a, Force>>,
        Option<Ref<'a, Torque>>,
        Option<Ref<'a, ForceAtPoint>>,
        Option<Ref<'a, Impulse>>,
    ),
    MadeOf<'a>,
);

/// What a body is made of and hangs from: any write to one of these wakes it (mass, density,
/// gravity scale, locks, collider, layers, inertia, drags, parent, children, friction,
/// restitution).
type MadeOf<'a> = (
    Option<Ref<'a, Mass>>,
    Option<Ref<'a, Density>>,
    Option<Ref<'a, GravityScale>>,
    Option<Ref<'a, LockedAxes>>,
    Option<Ref<'a, Collider>>,
    Option<Ref<'a, CollisionLayers>>,
    Option<Ref<'a, Inertia>>,
    Option<Ref<'a, LinearDrag>>,
    Option<Ref<'a, AngularDrag>>,
    Option<Ref<'a, ChildOf>>,
    Option<Ref<'a, Children>>,
    Option<Ref<'a, Friction>>,
    Option<Ref<'a, Restitution>>,
);

/// One sleeping table's data as [`SleeperColumns`] yields it.
type SleeperTable<'w, 's> =
    <SleeperColumns<'static> as bevy_ecs::query::ContiguousQueryData>::Contiguous<'w, 's>;

/// The make-up columns of one sleeping table.
type MadeOfTable<'w, 's> =
    <MadeOf<'static> as bevy_ecs::query::ContiguousQueryData>::Contiguous<'w, 's>;

/// Buffers of the check, kept from step to step.
#[derive(Default)]
pub(crate) struct WakeScratch {
    /// Per row of the table being read: [`TOUCHED`] and [`REMADE`] bits.
    rows: Vec<u8>,
    woken: Vec<Entity>,
    /// Whether the sleeping tables could not be read contiguously, and it was said.
    warned: bool,
}

/// A row some column of which was written since the last check.
const TOUCHED: u8 = 1;
/// A row whose body's make-up ([`MadeOf`]) was written.
const REMADE: u8 = 2;

/// Wakes sleeping bodies that game code moved, turned, set moving, pushed or reshaped since the
/// last step, and every body when gravity changed. Values the physics itself writes when a body
/// falls asleep (pose, velocities, a spent force) wake it only if they differ from what it
/// slept with; a write to anything else (mass, collider, drag, parent) wakes it. This covers
/// everything validation checks, so that validation and the other stages can leave sleeping
/// bodies out: a bad value written to a sleeper wakes it and is then validated.
#[allow(clippy::type_complexity)]
pub(crate) fn wake_on_game_changes(
    mut sleepers: ParamSet<(
        Query<SleeperColumns, With<Sleeping>>,
        Query<(Entity, &mut SleepState), With<Sleeping>>,
    )>,
    gravity: Option<Res<Gravity>>,
    mut unset: (
        RemovedComponents<Mass>,
        RemovedComponents<Density>,
        RemovedComponents<GravityScale>,
        RemovedComponents<LockedAxes>,
        RemovedComponents<CollisionLayers>,
    ),
    mut waker: Waker,
    mut scratch: Local<WakeScratch>,
) {
    if gravity.is_some_and(|g| g.is_changed()) {
        for (e, mut sleep) in &mut sleepers.p1() {
            waker.wake(e, Some(&mut sleep));
        }
        return;
    }
    let scratch = &mut *scratch;
    // A removed mass, density, gravity scale, lock or layers changes what the body weighs or
    // feels, how it may move or what it touches.
    let (mass, density, scale, locks, layers) = &mut unset;
    let removed = mass.read().chain(density.read()).chain(scale.read());
    scratch
        .woken
        .extend(removed.chain(locks.read()).chain(layers.read()));
    // Every component of the query is stored in tables, so the query is dense and
    // `contiguous_iter` does not fail; were one made a sparse set, the error says so.
    let readable = sleepers.p0();
    let cannot = "game writes cannot wake sleeping bodies";
    let tables = dense(readable.contiguous_iter(), &mut scratch.warned, cannot);
    for table in tables.into_iter().flatten() {
        check_table(table, &mut scratch.rows, &mut scratch.woken);
    }
    for e in scratch.woken.drain(..) {
        if let Ok((e, mut sleep)) = sleepers.p1().get_mut(e) {
            waker.wake(e, Some(&mut sleep));
        }
    }
}

/// Adds to `woken` the bodies of one sleeping table that game code woke; reads no row of a
/// table whose columns all say (by their summary ticks) that none was written.
fn check_table(table: SleeperTable<'_, '_>, rows: &mut Vec<u8>, woken: &mut Vec<Entity>) {
    let ((entities, states), (p, r, v, w), (f, t, fp, imp), made_of) = table;
    let (p, r, v) = (Column::new(p), Column::new(r), Column::new(v));
    let (w, f, t) = (Column::maybe(w), Column::maybe(f), Column::maybe(t));
    let (fp, imp) = (Column::maybe(fp), Column::maybe(imp));
    let motion_ticks = [p.written(), r.written(), v.written(), written(&w)];
    let push_ticks = [written(&f), written(&t), written(&fp), written(&imp)];
    let remade = remade_ticks(made_of);
    let mut columns = motion_ticks.iter().chain(&push_ticks).chain(&remade);
    if columns.all(Option::is_none) {
        return;
    }
    rows.clear();
    rows.resize(entities.len(), 0);
    for ticks in motion_ticks.into_iter().chain(push_ticks).flatten() {
        mark(rows, &ticks, TOUCHED);
    }
    for ticks in remade.iter().flatten() {
        mark(rows, ticks, TOUCHED | REMADE);
    }
    for (row, &flags) in rows.iter().enumerate().filter(|(_, flags)| **flags != 0) {
        let slept = &states[row];
        let pushed = at(&f, row).is_some_and(|f| f.0 != Vec3::ZERO)
            || at(&t, row).is_some_and(|t| t.0 != Vec3::ZERO)
            || at(&fp, row).is_some_and(|f| !f.is_empty())
            || at(&imp, row).is_some_and(|i| !i.is_empty());
        let spun = at(&w, row).is_some_and(|w| w.0 != Vec3::ZERO);
        let moved = p.values[row].0 != slept.at
            || r.values[row].0 != slept.orientation
            || v.values[row].0 != Vec3::ZERO;
        if pushed || spun || moved || flags & REMADE != 0 {
            woken.push(entities[row]);
        }
    }
}

/// The change ticks of the make-up columns some row of which was written.
fn remade_ticks<'w>(made_of: MadeOfTable<'w, '_>) -> [Option<ContiguousComponentTicksRef<'w>>; 13] {
    let (
        mass,
        density,
        scale,
        locks,
        collider,
        layers,
        inertia,
        drag,
        angular_drag,
        parent,
        children,
        friction,
        restitution,
    ) = made_of;
    [
        written_ticks(mass),
        written_ticks(density),
        written_ticks(scale),
        written_ticks(locks),
        written_ticks(collider),
        written_ticks(layers),
        written_ticks(inertia),
        written_ticks(drag),
        written_ticks(angular_drag),
        written_ticks(parent),
        written_ticks(children),
        written_ticks(friction),
        written_ticks(restitution),
    ]
}

/// One column of a sleeping table: its values, and its change ticks if its summary tick says
/// (or, without one, may say) that a row was written since the last check.
struct Column<'w, T> {
    values: &'w [T],
    ticks: Option<ContiguousComponentTicksRef<'w>>,
}

impl<'w, T> Column<'w, T> {
    fn new(column: ContiguousRef<'w, T>) -> Self {
        let (values, ticks) = ContiguousRef::split(column);
        Self {
            values,
            ticks: if_written(ticks),
        }
    }

    /// `None` for a column the table does not have.
    fn maybe(column: Option<ContiguousRef<'w, T>>) -> Option<Self> {
        column.map(Self::new)
    }

    fn written(&self) -> Option<ContiguousComponentTicksRef<'w>> {
        self.ticks.clone()
    }
}

/// The written ticks of an optional column.
fn written<'w, T>(column: &Option<Column<'w, T>>) -> Option<ContiguousComponentTicksRef<'w>> {
    column.as_ref().and_then(Column::written)
}

/// The value of an optional column at `row`.
fn at<'a, T>(column: &'a Option<Column<'_, T>>, row: usize) -> Option<&'a T> {
    column.as_ref().map(|c| &c.values[row])
}

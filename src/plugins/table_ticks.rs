//! Reading whole tables for writes: the shared steps of the checks that find game writes to
//! bodies the per-step change scans leave out (sleeping ones, `wake_on_writes`; settled
//! statics, `settle`). Bevy 0.20 keeps a summary tick per table column for components that ask
//! for one (`#[component(summary_tick)]`): the last time any of its rows was written. A column
//! whose summary says none was is passed over whole; the others' change ticks are read row by
//! row. Columns without a summary tick (Bevy's own `Transform`, `ChildOf`, `Children`) are
//! always read.

use bevy_ecs::change_detection::{ContiguousComponentTicksRef, ContiguousRef};
use bevy_ecs::query::QueryNotDenseError;

/// `ticks` if some row of their column may have been written since the check last ran (its
/// summary tick says so, or it has none).
pub(crate) fn if_written(
    ticks: ContiguousComponentTicksRef<'_>,
) -> Option<ContiguousComponentTicksRef<'_>> {
    (ticks.summary_tick_is_changed() != Some(false)).then_some(ticks)
}

/// The change ticks of an optional column whose values the check does not read, if some row
/// of it may have been written.
pub(crate) fn written_ticks<T>(
    column: Option<ContiguousRef<'_, T>>,
) -> Option<ContiguousComponentTicksRef<'_>> {
    column.and_then(|c| if_written(ContiguousRef::split(c).1))
}

/// Sets `bit` on the rows `ticks` says were written since the last check.
pub(crate) fn mark(rows: &mut [u8], ticks: &ContiguousComponentTicksRef<'_>, bit: u8) {
    for (flags, written) in rows.iter_mut().zip(ticks.is_changed_iter()) {
        *flags |= bit * u8::from(written);
    }
}

/// The tables of a contiguous iteration, or `None` for a query that is not dense (one of its
/// components made a sparse set), said once through `warned`: what the check then cannot do.
pub(crate) fn dense<T>(
    tables: Result<T, QueryNotDenseError>,
    warned: &mut bool,
    cannot: &str,
) -> Option<T> {
    match tables {
        Ok(tables) => Some(tables),
        Err(e) => {
            if !std::mem::replace(warned, true) {
                log::error!("urto: {cannot}: {e}");
            }
            None
        }
    }
}

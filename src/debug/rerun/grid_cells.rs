//! The static grid as a moving body sees it (the slides' "object vs static scene"): the cells
//! its bounding volume touches and the static objects those cells list.
//!
//! Read from [`BroadPhaseIndex::grid`] at the end of the step, with the volumes the bodies have
//! then. The candidates are drawn as the grid stores them (their AABBs), split into those whose
//! box also overlaps a moving body's (the pairs the narrow phase tests) and those only listed in
//! a shared cell (the grid's false positives, rejected by one box test).

use super::{RerunRecording, arr, color, report};
use crate::bounding::Aabb;
use crate::broad_phase::StaticGrid;
use crate::components::*;
use crate::plugins::BroadPhaseIndex;
use bevy_ecs::prelude::*;

/// A body touching more cells than this has only the outline of its cell range drawn.
const MAX_CELLS_PER_BODY: u128 = 1024;
/// Most cell boxes drawn per step, over all bodies; beyond it, ranges are drawn as outlines.
const MAX_CELLS_DRAWN: usize = 20_000;

const CELL_OCCUPIED: [u8; 3] = [0, 188, 212];
const CELL_EMPTY: [u8; 3] = [70, 100, 150];
const LISTED: [u8; 3] = [241, 196, 15];
const OVERLAPPING: [u8; 3] = [231, 76, 60];

/// Root bodies in the moving broad phase (dynamic and kinematic).
type MovingRoot = (
    With<Velocity>,
    Without<Static>,
    Without<ChildOf>,
    Without<Quarantined>,
);

/// What one recorded step draws, in buffers kept between steps.
#[derive(Default)]
pub(super) struct GridScratch {
    volumes: Vec<Aabb>,
    occupied_cells: Vec<Aabb>,
    empty_cells: Vec<Aabb>,
    ids: Vec<u32>,
    in_cell: Vec<u32>,
    listed: Vec<Aabb>,
    overlapping: Vec<Aabb>,
}

/// Logs `broad_phase/grid_cells/{occupied,empty}` and
/// `broad_phase/candidates/{listed,overlapping}`.
pub(super) fn record_grid_cells(
    rec: Res<RerunRecording>,
    index: Option<Res<BroadPhaseIndex>>,
    bodies: Query<&BoundingVolume, MovingRoot>,
    mut scratch: Local<GridScratch>,
) {
    if !rec.config.grid_cells {
        return;
    }
    let s = &mut *scratch;
    s.clear();
    s.volumes.extend(
        bodies
            .iter()
            .map(|bv| bv.0)
            .filter(|b| b.is_valid() && b.is_finite()),
    );
    if let Some(index) = index.filter(|i| !i.grid().is_empty()) {
        s.collect_cells(index.grid());
        s.classify_candidates(index.grid());
    }
    let stream = &rec.stream;
    let wire = |boxes: &[Aabb], tint: [u8; 3]| {
        rerun::Boxes3D::from_centers_and_half_sizes(
            boxes.iter().map(|b| arr(b.center())),
            boxes.iter().map(|b| arr(b.half_extents())),
        )
        .with_colors([color(tint)])
    };
    // Candidates are drawn solid and a little larger than the buildings they cover, so they
    // stand out from the grey scenery without flickering against it.
    let solid = |boxes: &[Aabb], tint: [u8; 3]| {
        rerun::Boxes3D::from_centers_and_half_sizes(
            boxes.iter().map(|b| arr(b.center())),
            boxes
                .iter()
                .map(|b| arr(b.half_extents() + 0.01 * b.half_extents().max_element() + 0.01)),
        )
        .with_colors([color(tint)])
        .with_fill_mode(rerun::FillMode::Solid)
    };
    let cells = "broad_phase/grid_cells";
    report(stream.log(
        format!("{cells}/occupied"),
        &wire(&s.occupied_cells, CELL_OCCUPIED),
    ));
    report(stream.log(format!("{cells}/empty"), &wire(&s.empty_cells, CELL_EMPTY)));
    let candidates = "broad_phase/candidates";
    report(stream.log(format!("{candidates}/listed"), &solid(&s.listed, LISTED)));
    report(stream.log(
        format!("{candidates}/overlapping"),
        &solid(&s.overlapping, OVERLAPPING),
    ));
}

impl GridScratch {
    fn clear(&mut self) {
        self.volumes.clear();
        self.occupied_cells.clear();
        self.empty_cells.clear();
        self.ids.clear();
        self.listed.clear();
        self.overlapping.clear();
    }

    /// The cells of every body's volume (split by whether they list statics), and the ids they
    /// list, plus the oversize objects every query reads; ids sorted, each once.
    fn collect_cells(&mut self, grid: &StaticGrid) {
        for volume in &self.volumes {
            let Ok(range) = grid.cells_touching(volume) else {
                continue;
            };
            let drawn = self.occupied_cells.len() + self.empty_cells.len();
            if range.cell_count() > MAX_CELLS_PER_BODY || drawn >= MAX_CELLS_DRAWN {
                self.empty_cells.push(grid.range_bounds(&range));
                continue;
            }
            for cell in range.iter() {
                grid.objects_in_cell(cell, &mut self.in_cell);
                let boxes = if self.in_cell.is_empty() {
                    &mut self.empty_cells
                } else {
                    &mut self.occupied_cells
                };
                boxes.push(grid.cell_bounds(cell));
                self.ids.extend_from_slice(&self.in_cell);
            }
        }
        if !self.volumes.is_empty() {
            grid.oversize_ids(&mut self.in_cell);
            self.ids.extend_from_slice(&self.in_cell);
        }
        self.ids.sort_unstable();
        self.ids.dedup();
    }

    /// Splits the candidates by whether their box overlaps some moving body's volume.
    fn classify_candidates(&mut self, grid: &StaticGrid) {
        for b in self.ids.iter().filter_map(|&id| grid.aabb(id)) {
            if self.volumes.iter().any(|v| v.intersects(&b)) {
                self.overlapping.push(b);
            } else {
                self.listed.push(b);
            }
        }
    }
}

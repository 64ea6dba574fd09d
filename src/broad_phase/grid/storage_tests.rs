//! Tests of the static grid's storage: refused input, placement in cells, removal, oversize
//! objects, the scan fallbacks, statistics and memory.

use super::*;
use crate::broad_phase::grid::stats::GridQueryStats;

fn unit_box(min: Vec3) -> Aabb {
    Aabb::new(min, min + Vec3::ONE)
}

fn cubes(size: f32) -> StaticGrid {
    StaticGrid::new(StaticGridConfig::with_cell_size(size)).unwrap()
}

fn query_ids(grid: &mut StaticGrid, query: Aabb) -> Vec<u32> {
    let mut out = Vec::new();
    grid.query(&query, &mut out).unwrap();
    out
}

#[test]
fn bad_boxes_and_ids_are_refused_and_leave_the_grid_unchanged() {
    let mut grid = cubes(1.0);
    grid.insert(1, unit_box(Vec3::ZERO)).unwrap();
    let nan = Aabb::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::ONE);
    let inverted = Aabb::new(Vec3::ONE, Vec3::ZERO);
    assert_eq!(
        grid.insert(2, nan),
        Err(GridError::NonFiniteAabb { id: Some(2) })
    );
    assert_eq!(
        grid.insert(2, Aabb::EMPTY),
        Err(GridError::NonFiniteAabb { id: Some(2) })
    );
    assert_eq!(
        grid.insert(2, inverted),
        Err(GridError::InvertedAabb { id: Some(2) })
    );
    assert_eq!(
        grid.insert(1, unit_box(Vec3::ONE)),
        Err(GridError::DuplicateId(1))
    );
    assert_eq!(grid.remove(7), Err(GridError::UnknownId(7)));
    assert_eq!(
        grid.update(7, unit_box(Vec3::ZERO)),
        Err(GridError::UnknownId(7))
    );
    assert_eq!(
        grid.update(1, nan),
        Err(GridError::NonFiniteAabb { id: Some(1) })
    );
    let mut out = vec![99];
    assert_eq!(
        grid.query(&nan, &mut out),
        Err(GridError::NonFiniteAabb { id: None })
    );
    assert_eq!(
        grid.query(&inverted, &mut out),
        Err(GridError::InvertedAabb { id: None })
    );
    assert_eq!(out, vec![99]);
    assert_eq!(grid.len(), 1);
    assert_eq!(grid.aabb(1), Some(unit_box(Vec3::ZERO)));
}

#[test]
fn a_bulk_insert_with_one_bad_object_inserts_nothing() {
    let mut grid = cubes(1.0);
    grid.insert(5, unit_box(Vec3::ZERO)).unwrap();
    let repeated = [
        (1, unit_box(Vec3::ZERO)),
        (2, unit_box(Vec3::ONE)),
        (1, unit_box(Vec3::ONE)),
    ];
    assert_eq!(grid.insert_bulk(&repeated), Err(GridError::DuplicateId(1)));
    let clash = [(1, unit_box(Vec3::ZERO)), (5, unit_box(Vec3::ONE))];
    assert_eq!(grid.insert_bulk(&clash), Err(GridError::DuplicateId(5)));
    let bad = [(1, unit_box(Vec3::ZERO)), (2, Aabb::EMPTY)];
    assert_eq!(
        grid.insert_bulk(&bad),
        Err(GridError::NonFiniteAabb { id: Some(2) })
    );
    assert_eq!(grid.len(), 1);
    assert_eq!(
        StaticGrid::build(&repeated).err(),
        Some(GridError::DuplicateId(1))
    );
}

#[test]
fn bad_configurations_are_refused() {
    let zero = StaticGridConfig::with_cell_size(0.0);
    assert_eq!(
        StaticGrid::new(zero).err(),
        Some(GridError::InvalidCellSize(Vec3::ZERO))
    );
    let greedy = StaticGridConfig {
        max_cells_per_object: u32::MAX,
        ..StaticGridConfig::default()
    };
    assert_eq!(
        StaticGrid::new(greedy).err(),
        Some(GridError::InvalidCellBudget(u32::MAX))
    );
}

#[test]
fn the_default_grid_is_the_checked_default_configuration() {
    let checked = StaticGrid::new(StaticGridConfig::default()).unwrap();
    let default = StaticGrid::default();
    assert_eq!(default.cell_size(), checked.cell_size());
    assert_eq!(
        default.max_cells_per_object(),
        checked.max_cells_per_object()
    );
    assert!(default.is_empty());
}

#[test]
fn build_picks_the_cell_size_from_the_objects_unless_told() {
    let objects: Vec<(u32, Aabb)> = (0..20)
        .map(|i| (i, Aabb::new(Vec3::ZERO, Vec3::new(2.0, 2.0, 6.0))))
        .collect();
    assert_eq!(
        StaticGrid::build(&objects).unwrap().cell_size(),
        Vec3::new(2.0, 2.0, 6.0)
    );
    let told = StaticGrid::build_with(&objects, StaticGridConfig::with_cell_size(0.5)).unwrap();
    assert_eq!(told.cell_size(), Vec3::splat(0.5));
    assert_eq!(
        StaticGrid::new(StaticGridConfig::default())
            .unwrap()
            .cell_size(),
        DEFAULT_CELL_SIZE
    );
}

#[test]
fn an_object_is_listed_in_exactly_the_cells_it_touches() {
    let mut grid = cubes(1.0);
    // [-0.5, 1.0] touches cells -1, 0 and 1 on x (its max face lies on the 0|1 boundary).
    grid.insert(
        3,
        Aabb::new(Vec3::new(-0.5, 0.2, 0.2), Vec3::new(1.0, 0.8, 0.8)),
    )
    .unwrap();
    assert_eq!(grid.occupied_cell_count(), 3);
    let mut out = Vec::new();
    for x in -1..=1 {
        grid.objects_in_cell(CellCoord::new(x, 0, 0), &mut out);
        assert_eq!(out, vec![3]);
    }
    grid.objects_in_cell(CellCoord::new(2, 0, 0), &mut out);
    assert!(out.is_empty());
}

#[test]
fn removal_empties_cells_and_reinsertion_reuses_the_slot() {
    let mut grid = cubes(1.0);
    grid.insert(1, unit_box(Vec3::ZERO)).unwrap();
    grid.insert(2, unit_box(Vec3::splat(5.0))).unwrap();
    let cells_with_both = grid.occupied_cell_count();
    assert_eq!(grid.remove(1), Ok(unit_box(Vec3::ZERO)));
    assert!(grid.occupied_cell_count() < cells_with_both);
    assert!(query_ids(&mut grid, unit_box(Vec3::ZERO)).is_empty());
    grid.insert(7, unit_box(Vec3::ZERO)).unwrap();
    assert_eq!(grid.objects.len(), 2, "the freed slot is reused");
    assert_eq!(grid.occupied_cell_count(), cells_with_both);
    assert_eq!(
        query_ids(&mut grid, Aabb::new(Vec3::ZERO, Vec3::splat(5.0))),
        vec![2, 7]
    );
}

#[test]
fn an_update_within_the_same_cells_touches_no_cell() {
    let mut grid = cubes(10.0);
    grid.insert(1, unit_box(Vec3::splat(1.0))).unwrap();
    let cells = grid.cells.clone();
    grid.update(1, unit_box(Vec3::splat(2.0))).unwrap();
    assert_eq!(grid.cells, cells);
    assert!(query_ids(&mut grid, unit_box(Vec3::splat(1.0))).contains(&1));
    assert!(query_ids(&mut grid, Aabb::new(Vec3::splat(0.5), Vec3::splat(1.5))).is_empty());
    grid.update(1, unit_box(Vec3::splat(25.0))).unwrap();
    assert_eq!(query_ids(&mut grid, unit_box(Vec3::splat(25.5))), vec![1]);
    assert_eq!(grid.occupied_cell_count(), 1);
}

#[test]
fn huge_objects_go_to_the_oversize_list_and_are_always_tested() {
    let mut grid = cubes(1.0);
    let ground = Aabb::new(
        Vec3::new(-1.0e5, -1.0e5, -1.0),
        Vec3::new(1.0e5, 1.0e5, 0.0),
    );
    grid.insert(0, ground).unwrap();
    grid.insert(1, unit_box(Vec3::ZERO)).unwrap();
    assert_eq!(grid.is_oversize(0), Some(true));
    assert_eq!(grid.is_oversize(1), Some(false));
    assert_eq!(grid.is_oversize(2), None);
    assert_eq!(grid.occupied_cell_count(), 8);
    let mut out = Vec::new();
    grid.oversize_ids(&mut out);
    assert_eq!(out, vec![0]);
    assert_eq!(
        query_ids(&mut grid, unit_box(Vec3::new(50.0, 50.0, -0.5))),
        vec![0]
    );
    assert!(query_ids(&mut grid, unit_box(Vec3::new(50.0, 50.0, 0.5))).is_empty());
    // Shrinking it brings it back into the cells; removing it empties the list.
    grid.update(0, unit_box(Vec3::splat(3.0))).unwrap();
    assert_eq!(grid.oversize_count(), 0);
    grid.update(0, ground).unwrap();
    grid.insert(2, ground).unwrap();
    grid.remove(0).unwrap();
    grid.oversize_ids(&mut out);
    assert_eq!(out, vec![2]);
    assert_eq!(grid.is_oversize(2), Some(true));
}

#[test]
fn a_zero_budget_turns_the_grid_into_a_scan() {
    let config = StaticGridConfig {
        max_cells_per_object: 0,
        ..StaticGridConfig::with_cell_size(1.0)
    };
    let mut grid = StaticGrid::new(config).unwrap();
    grid.insert_bulk(&[(4, unit_box(Vec3::ZERO)), (9, unit_box(Vec3::splat(3.0)))])
        .unwrap();
    assert_eq!(grid.occupied_cell_count(), 0);
    assert_eq!(
        query_ids(&mut grid, Aabb::new(Vec3::ZERO, Vec3::splat(3.0))),
        vec![4, 9]
    );
}

#[test]
fn a_world_sized_query_scans_objects_instead_of_cells() {
    let mut grid = cubes(0.001);
    grid.insert(1, unit_box(Vec3::ZERO).expanded(-0.4995))
        .unwrap();
    grid.insert(2, unit_box(Vec3::splat(100.0)).expanded(-0.4995))
        .unwrap();
    let world = Aabb::new(Vec3::splat(-1.0e30), Vec3::splat(1.0e30));
    let mut out = Vec::new();
    let stats = grid.query(&world, &mut out).unwrap();
    assert_eq!(out, vec![1, 2]);
    assert_eq!(stats.object_scans, 1);
    assert_eq!(stats.cells_visited, 0);
    assert_eq!(stats.exact_tests, 2);
    let candidates = grid.query_candidates(&world, &mut out).unwrap();
    assert_eq!(out, vec![1, 2]);
    assert_eq!(candidates.exact_tests, 0);
}

#[test]
fn a_query_far_from_every_object_visits_no_cell() {
    let mut grid = cubes(1.0);
    grid.insert(1, unit_box(Vec3::ZERO)).unwrap();
    let mut out = Vec::new();
    let stats = grid
        .query(&unit_box(Vec3::splat(-500.0)), &mut out)
        .unwrap();
    assert!(out.is_empty());
    assert_eq!(stats, GridQueryStats::default());
}

#[test]
fn stats_count_cells_entries_and_distinct_tests() {
    let mut grid = cubes(1.0);
    // Object 1 spans 2 × 1 × 1 cells, object 2 one of them.
    grid.insert(1, Aabb::new(Vec3::splat(0.1), Vec3::new(1.9, 0.9, 0.9)))
        .unwrap();
    grid.insert(2, Aabb::new(Vec3::splat(0.2), Vec3::splat(0.3)))
        .unwrap();
    let mut out = Vec::new();
    let query = Aabb::new(Vec3::new(0.5, 0.5, 0.5), Vec3::new(1.5, 0.6, 0.6));
    let stats = grid.query(&query, &mut out).unwrap();
    assert_eq!(out, vec![1]);
    assert_eq!(stats.cells_visited, 2);
    assert_eq!(stats.candidates_listed, 3);
    assert_eq!(stats.exact_tests, 2);
    let candidates = grid.query_candidates(&query, &mut out).unwrap();
    assert_eq!(out, vec![1, 2]);
    assert_eq!(candidates.exact_tests, 0);
}

#[test]
fn the_generation_counter_wraps_without_false_duplicates() {
    let mut grid = cubes(1.0);
    grid.insert(1, Aabb::new(Vec3::ZERO, Vec3::splat(1.5)))
        .unwrap();
    // Enough other objects that an 8-cell query visits cells instead of scanning.
    for id in 2..12 {
        grid.insert(id, unit_box(Vec3::new(0.0, 0.0, id as f32 * 2.0)))
            .unwrap();
    }
    let query = Aabb::new(Vec3::splat(0.5), Vec3::splat(1.2));
    grid.generation = u32::MAX - 1;
    for _ in 0..4 {
        let mut out = Vec::new();
        let stats = grid.query(&query, &mut out).unwrap();
        assert_eq!(out, vec![1]);
        assert_eq!(
            (
                stats.cells_visited,
                stats.candidates_listed,
                stats.exact_tests
            ),
            (8, 8, 1)
        );
    }
    assert_eq!(
        grid.generation, 3,
        "wrapped past zero to 1, then two more queries"
    );
}

#[test]
fn cell_bounds_cover_the_cells_a_box_touches() {
    let grid = StaticGrid::new(StaticGridConfig::with_cell_size_per_axis(Vec3::new(
        2.0, 3.0, 0.5,
    )))
    .unwrap();
    let aabb = Aabb::new(Vec3::new(-3.0, 1.0, 0.1), Vec3::new(1.0, 4.0, 0.2));
    let range = grid.cells_touching(&aabb).unwrap();
    assert_eq!(range.cell_count(), 3 * 2);
    let covered = grid.range_bounds(&range);
    assert!(covered.contains(&aabb));
    for cell in range.iter() {
        assert!(grid.cell_bounds(cell).intersects(&aabb));
    }
    assert!(grid.cells_touching(&Aabb::EMPTY).is_err());
}

#[test]
fn memory_grows_with_objects_and_stays_bounded_for_huge_ones() {
    let objects: Vec<(u32, Aabb)> = (0..100)
        .map(|i| (i, unit_box(Vec3::new(i as f32 * 3.0, 0.0, 0.0))))
        .collect();
    let empty = cubes(1.0).memory_bytes();
    let mut with_small = cubes(1.0);
    with_small.insert_bulk(&objects).unwrap();
    let hundred = with_small.memory_bytes();
    // At least the objects' records plus one 4-byte entry in each of their 8 cells.
    assert!(hundred > empty + 100 * size_of::<SlotObject>() + 800 * size_of::<u32>());
    let mut with_huge = with_small.clone();
    with_small
        .insert(1000, unit_box(Vec3::splat(-50.0)))
        .unwrap();
    with_huge
        .insert(1000, Aabb::new(Vec3::splat(-1.0e6), Vec3::splat(1.0e6)))
        .unwrap();
    // A box over ~10¹⁸ cells costs about what a unit box does: one oversize-list entry.
    assert!(with_huge.memory_bytes() <= with_small.memory_bytes() + 64);
    assert_eq!(with_huge.occupied_cell_count(), 800);
}

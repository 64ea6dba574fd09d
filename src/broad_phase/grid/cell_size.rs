//! The automatic cell size of a [`StaticGrid`](super::storage::StaticGrid).
//!
//! A uniform grid works when cells are about as large as the objects in them (the slides'
//! "griglia uniforme"; Ericson 2005, *Real-Time Collision Detection*, §7.1.2): much smaller cells
//! make each object touch many cells (memory, insertion time), much larger ones put many
//! objects in each cell (candidates that fail the exact test). The rule:
//!
//! 1. **Per axis, the 90th percentile of the objects' extents** along that axis. An object no
//!    larger than the cell on an axis touches at most 2 cells along it, so most objects touch
//!    at most 2×2×2 = 8 cells; the few larger ones do not drag the size up for everybody.
//!    Cells may be anisotropic: in a town, buildings are taller than wide, and cubic cells sized
//!    by height would pile several buildings into each cell.
//! 2. **No axis below 1/8 of the largest**: a scene of flat tiles would otherwise get razor-thin
//!    cells, and an ordinary moving box would span dozens of them vertically.
//! 3. **Scenes of points** (every extent zero) get cubic cells holding about one object each:
//!    the `d`-th root of the volume (area, length) per object, over the `d` axes the points
//!    spread on. All points coincident, or no objects at all: [`DEFAULT_CELL_SIZE`].
//!
//! The result is clamped to the accepted range
//! ([`MIN_CELL_SIZE`]..=[`MAX_CELL_SIZE`]). Callers who know better (e.g. the size of the moving
//! bodies that will query) override it through
//! [`StaticGridConfig::cell_size`](super::config::StaticGridConfig::cell_size).

use super::config::{MAX_CELL_SIZE, MIN_CELL_SIZE};
use crate::bounding::Aabb;
use glam::{DVec3, Vec3};

/// Cell size for a grid with no objects to measure.
pub const DEFAULT_CELL_SIZE: Vec3 = Vec3::ONE;

/// Which percentile of the per-axis object extents sets the cell size (rule 1).
pub const CELL_SIZE_PERCENTILE: f64 = 0.9;

/// Largest ratio between the longest and the shortest side of a cell (rule 2).
pub const MAX_CELL_ASPECT: f32 = 8.0;

/// The cell size the module rule picks for these boxes. Boxes that are not finite or have
/// `min > max` are ignored (the grid refuses them anyway).
pub fn suggest_cell_size<'a>(aabbs: impl IntoIterator<Item = &'a Aabb>) -> Vec3 {
    let mut extents: [Vec<f32>; 3] = Default::default();
    let mut bounds = Aabb::EMPTY;
    for aabb in aabbs {
        if !aabb.is_finite() || !aabb.is_valid() {
            continue;
        }
        // `max - min` of finite values can still overflow to infinity.
        let extent = aabb.extents().min(Vec3::splat(MAX_CELL_SIZE));
        for (axis, list) in extents.iter_mut().enumerate() {
            list.push(extent[axis]);
        }
        bounds = bounds.union(aabb);
    }
    let count = extents[0].len();
    if count == 0 {
        return DEFAULT_CELL_SIZE;
    }
    let per_axis = Vec3::new(
        percentile(&mut extents[0], CELL_SIZE_PERCENTILE),
        percentile(&mut extents[1], CELL_SIZE_PERCENTILE),
        percentile(&mut extents[2], CELL_SIZE_PERCENTILE),
    );
    let largest = per_axis.max_element();
    let size = if largest > 0.0 {
        per_axis.max(Vec3::splat(largest / MAX_CELL_ASPECT))
    } else {
        spacing_of_points(&bounds, count)
    };
    size.clamp(Vec3::splat(MIN_CELL_SIZE), Vec3::splat(MAX_CELL_SIZE))
}

/// The `fraction` percentile of a non-empty list by the nearest-rank method (the smallest value
/// that at least `fraction` of the list does not exceed), reordering the list.
fn percentile(values: &mut [f32], fraction: f64) -> f32 {
    let at_or_below = (values.len() as f64 * fraction).ceil() as usize;
    let rank = at_or_below.clamp(1, values.len()) - 1;
    let (_, value, _) = values.select_nth_unstable_by(rank, f32::total_cmp);
    *value
}

/// Cubic cells of about one point each (rule 3), in `f64` because the spread of finite `f32`
/// coordinates can exceed `f32::MAX`.
fn spacing_of_points(bounds: &Aabb, count: usize) -> Vec3 {
    let spread = bounds.max.as_dvec3() - bounds.min.as_dvec3();
    let axes: Vec<f64> = spread.to_array().into_iter().filter(|&e| e > 0.0).collect();
    if axes.is_empty() {
        return DEFAULT_CELL_SIZE;
    }
    let per_object = axes.iter().product::<f64>() / count as f64;
    let side = per_object.powf(1.0 / axes.len() as f64);
    if side.is_finite() && side > 0.0 {
        DVec3::splat(side).as_vec3()
    } else {
        DEFAULT_CELL_SIZE
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(center: Vec3, half: Vec3) -> Aabb {
        Aabb::from_center_half_extents(center, half)
    }

    #[test]
    fn the_percentile_bounds_at_least_that_fraction() {
        for n in 1..60 {
            let mut values: Vec<f32> = (0..n).rev().map(|i| i as f32).collect();
            let p = percentile(&mut values, CELL_SIZE_PERCENTILE);
            let below = values.iter().filter(|&&v| v <= p).count();
            assert!(
                below as f64 >= CELL_SIZE_PERCENTILE * n as f64,
                "{below} of {n}"
            );
            assert!(
                ((below - 1) as f64) < CELL_SIZE_PERCENTILE * n as f64,
                "not the smallest"
            );
        }
    }

    #[test]
    fn no_objects_give_the_default() {
        assert_eq!(suggest_cell_size(&[]), DEFAULT_CELL_SIZE);
        let invalid = [Aabb::EMPTY, Aabb::new(Vec3::ONE, Vec3::ZERO)];
        assert_eq!(suggest_cell_size(&invalid), DEFAULT_CELL_SIZE);
    }

    #[test]
    fn a_few_giants_do_not_set_the_size() {
        // 95 unit boxes and 5 boxes a hundred times larger: the cell fits the unit boxes.
        let mut boxes: Vec<Aabb> = (0..95)
            .map(|i| cube(Vec3::new(i as f32 * 3.0, 0.0, 0.0), Vec3::splat(0.5)))
            .collect();
        boxes
            .extend((0..5).map(|i| cube(Vec3::new(0.0, i as f32 * 300.0, 0.0), Vec3::splat(50.0))));
        assert_eq!(suggest_cell_size(&boxes), Vec3::ONE);
    }

    #[test]
    fn tall_buildings_get_tall_cells() {
        let boxes: Vec<Aabb> = (0..50)
            .map(|i| {
                cube(
                    Vec3::new(i as f32 * 10.0, 0.0, 0.0),
                    Vec3::new(2.0, 2.0, 15.0),
                )
            })
            .collect();
        assert_eq!(suggest_cell_size(&boxes), Vec3::new(4.0, 4.0, 30.0));
    }

    #[test]
    fn flat_tiles_do_not_get_razor_thin_cells() {
        let boxes: Vec<Aabb> = (0..50)
            .map(|i| {
                cube(
                    Vec3::new(i as f32 * 10.0, 0.0, 0.0),
                    Vec3::new(4.0, 4.0, 0.0),
                )
            })
            .collect();
        let size = suggest_cell_size(&boxes);
        assert_eq!(size, Vec3::new(8.0, 8.0, 8.0 / MAX_CELL_ASPECT));
    }

    #[test]
    fn points_get_cells_of_about_one_point_each() {
        // 100 points on a 10 × 10 lattice of spacing 2 span 18 × 18: 3.24 area units each.
        let points: Vec<Aabb> = (0..100)
            .map(|i| {
                let p = Vec3::new((i % 10) as f32 * 2.0, (i / 10) as f32 * 2.0, 5.0);
                Aabb::new(p, p)
            })
            .collect();
        let size = suggest_cell_size(&points);
        approx::assert_relative_eq!(size.x, 1.8, epsilon = 1e-5);
        assert_eq!(size.x, size.y);
        assert_eq!(size.x, size.z);
    }

    #[test]
    fn coincident_points_and_huge_spreads_stay_in_range() {
        let p = Aabb::new(Vec3::splat(7.0), Vec3::splat(7.0));
        assert_eq!(suggest_cell_size(&[p, p]), DEFAULT_CELL_SIZE);
        let far = [
            Aabb::new(Vec3::splat(-3.0e38), Vec3::splat(-3.0e38)),
            Aabb::new(Vec3::splat(3.0e38), Vec3::splat(3.0e38)),
        ];
        let size = suggest_cell_size(&far);
        assert!(
            size.cmple(Vec3::splat(MAX_CELL_SIZE)).all()
                && size.cmpge(Vec3::splat(MIN_CELL_SIZE)).all()
        );
        let slab = [Aabb::new(Vec3::splat(-3.0e38), Vec3::splat(3.0e38))];
        assert_eq!(suggest_cell_size(&slab), Vec3::splat(MAX_CELL_SIZE));
    }
}

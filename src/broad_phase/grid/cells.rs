//! Cell coordinates of a uniform grid, and the box of cells an AABB touches.
//!
//! A point `p` lies in cell `floor(p / cell_size)` on each axis. The grid never needs that map
//! to be exact, only **monotone**: if `a <= b` then `cell(a) <= cell(b)`. Then an object box and
//! a query box that share a point `x` both contain `cell(x)` in their cell ranges, so a query
//! that visits its cells meets every object it intersects, touching boxes included. Rounded
//! multiplication by a positive constant, `floor`, and Rust's saturating float-to-int cast are
//! all monotone, so the map stays correct where it stops being exact: far from the origin
//! (rounding merges or skips a cell boundary, never reorders) and beyond the `i32` range
//! (coordinates saturate into the outermost cells, which then simply hold more objects).

use crate::bounding::Aabb;
use glam::{IVec3, Vec3};

/// The integer coordinates of one cell: cell `c` covers `[c * size, (c + 1) * size)` per axis.
pub type CellCoord = IVec3;

/// The cell holding `p` on each axis, given the reciprocal of the cell size.
///
/// `p` must be finite (the grid checks boxes before calling this); the product may still
/// overflow to an infinity, which the saturating cast maps to `i32::MIN`/`i32::MAX`.
#[inline]
pub(crate) fn cell_of_point(p: Vec3, inv_cell_size: Vec3) -> CellCoord {
    let scaled = p * inv_cell_size;
    IVec3::new(
        floor_to_i32(scaled.x),
        floor_to_i32(scaled.y),
        floor_to_i32(scaled.z),
    )
}

/// `floor(x)` clamped to the `i32` range, without a call to `floorf` (baseline x86-64 has no
/// rounding instruction, and the call was a tenth of a query's time).
///
/// `x as i32` truncates towards zero and saturates; one less when truncation went up (negative
/// non-integers) gives the floor. Where `|x| >= 2²⁴` every `f32` is an integer, so the
/// comparison is exact; below `i32::MIN` the subtraction saturates instead of overflowing.
#[inline]
fn floor_to_i32(x: f32) -> i32 {
    let truncated = x as i32;
    truncated.saturating_sub(i32::from(truncated as f32 > x))
}

/// A box of cells, both corners included: the cells an AABB touches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CellRange {
    /// Lowest cell on each axis.
    pub min: CellCoord,
    /// Highest cell on each axis (included).
    pub max: CellCoord,
}

impl CellRange {
    /// The cells a finite AABB touches (closed box: a face on a cell boundary touches the cell
    /// beyond it too).
    #[inline]
    pub(crate) fn of_aabb(aabb: &Aabb, inv_cell_size: Vec3) -> Self {
        Self {
            min: cell_of_point(aabb.min, inv_cell_size),
            max: cell_of_point(aabb.max, inv_cell_size),
        }
    }

    /// Cells along each axis, as `u64` (a span can reach 2³² cells).
    fn spans(&self) -> [u64; 3] {
        let span = |lo: i32, hi: i32| (i64::from(hi) - i64::from(lo) + 1).max(0) as u64;
        [
            span(self.min.x, self.max.x),
            span(self.min.y, self.max.y),
            span(self.min.z, self.max.z),
        ]
    }

    /// Number of cells in the range. `u128` because a range over the whole `i32` cube holds
    /// 2⁹⁶ cells; callers compare this with a budget before visiting anything.
    pub fn cell_count(&self) -> u128 {
        self.spans().iter().map(|&s| u128::from(s)).product()
    }

    /// True when `cell` lies in the range.
    pub fn contains(&self, cell: CellCoord) -> bool {
        self.min.cmple(cell).all() && cell.cmple(self.max).all()
    }

    /// True when the two ranges share a cell.
    pub fn overlaps(&self, other: &CellRange) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }

    /// The cells both ranges hold, `None` when they share none.
    pub fn intersection(&self, other: &CellRange) -> Option<CellRange> {
        self.overlaps(other).then(|| CellRange {
            min: self.min.max(other.min),
            max: self.max.min(other.max),
        })
    }

    /// The smallest range holding both.
    #[must_use]
    pub fn union(&self, other: &CellRange) -> CellRange {
        CellRange {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The cells in a fixed order: x fastest, then y, then z.
    ///
    /// The range may be astronomically large; check [`CellRange::cell_count`] first.
    pub fn iter(&self) -> CellRangeIter {
        CellRangeIter {
            range: *self,
            next: Some(self.min),
        }
    }
}

impl IntoIterator for CellRange {
    type Item = CellCoord;
    type IntoIter = CellRangeIter;

    fn into_iter(self) -> CellRangeIter {
        self.iter()
    }
}

impl IntoIterator for &CellRange {
    type Item = CellCoord;
    type IntoIter = CellRangeIter;

    fn into_iter(self) -> CellRangeIter {
        self.iter()
    }
}

/// Iterator over a [`CellRange`], x fastest; see [`CellRange::iter`].
#[derive(Clone, Debug)]
pub struct CellRangeIter {
    range: CellRange,
    next: Option<CellCoord>,
}

impl Iterator for CellRangeIter {
    type Item = CellCoord;

    #[inline]
    fn next(&mut self) -> Option<CellCoord> {
        let current = self.next?;
        let (lo, hi) = (self.range.min, self.range.max);
        // Compare before incrementing so that a range ending at `i32::MAX` never overflows.
        self.next = if current.x < hi.x {
            Some(IVec3::new(current.x + 1, current.y, current.z))
        } else if current.y < hi.y {
            Some(IVec3::new(lo.x, current.y + 1, current.z))
        } else if current.z < hi.z {
            Some(IVec3::new(lo.x, lo.y, current.z + 1))
        } else {
            None
        };
        Some(current)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negative_coordinates_floor_towards_minus_infinity() {
        let inv = Vec3::ONE;
        assert_eq!(
            cell_of_point(Vec3::new(-0.5, -1.0, -1.5), inv),
            IVec3::new(-1, -1, -2)
        );
        assert_eq!(
            cell_of_point(Vec3::new(0.0, 0.999, 1.0), inv),
            IVec3::new(0, 0, 1)
        );
    }

    #[test]
    fn the_floor_matches_the_library_floor_clamped_to_the_integer_range() {
        let samples = [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            1.5,
            -1.5,
            2.9999998,
            -2.9999998,
            8388607.5,
            -8388607.5,
            16777217.0,
            -16777217.0,
            2147483520.0,
            -2147483648.0,
            2147483648.0,
            -2147483904.0,
            3.0e9,
            -3.0e9,
            f32::MAX,
            -f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            1.0e-40,
            -1.0e-40,
        ];
        for x in samples {
            let expected = x.floor().clamp(i32::MIN as f32, i32::MAX as f32) as i32;
            assert_eq!(floor_to_i32(x), expected, "floor of {x}");
        }
    }

    #[test]
    fn coordinates_beyond_the_integer_range_saturate() {
        let inv = Vec3::splat(1.0e6);
        let c = cell_of_point(Vec3::new(3.0e38, -3.0e38, 1.0e30), inv);
        assert_eq!(c, IVec3::new(i32::MAX, i32::MIN, i32::MAX));
    }

    #[test]
    fn a_face_on_a_cell_boundary_touches_both_cells() {
        let b = Aabb::new(Vec3::new(0.25, 0.25, 0.25), Vec3::new(2.0, 0.5, 0.5));
        let r = CellRange::of_aabb(&b, Vec3::ONE);
        assert_eq!(r.min, IVec3::ZERO);
        assert_eq!(r.max, IVec3::new(2, 0, 0));
        assert_eq!(r.cell_count(), 3);
    }

    #[test]
    fn iteration_visits_every_cell_once_in_x_fastest_order() {
        let r = CellRange {
            min: IVec3::new(-1, 5, -3),
            max: IVec3::new(1, 6, -2),
        };
        let cells: Vec<_> = r.iter().collect();
        assert_eq!(cells.len() as u128, r.cell_count());
        let mut expected = Vec::new();
        for z in -3..=-2 {
            for y in 5..=6 {
                for x in -1..=1 {
                    expected.push(IVec3::new(x, y, z));
                }
            }
        }
        assert_eq!(cells, expected);
    }

    #[test]
    fn iteration_at_the_edge_of_the_integer_range_stops() {
        let r = CellRange {
            min: IVec3::splat(i32::MAX - 1),
            max: IVec3::splat(i32::MAX),
        };
        assert_eq!(r.iter().count(), 8);
    }

    #[test]
    fn the_whole_integer_cube_is_counted_without_overflow() {
        let r = CellRange {
            min: IVec3::splat(i32::MIN),
            max: IVec3::splat(i32::MAX),
        };
        assert_eq!(r.cell_count(), 1u128 << 96);
    }

    #[test]
    fn intersection_and_overlap_agree() {
        let a = CellRange {
            min: IVec3::ZERO,
            max: IVec3::splat(3),
        };
        let b = CellRange {
            min: IVec3::splat(3),
            max: IVec3::splat(5),
        };
        let c = CellRange {
            min: IVec3::splat(4),
            max: IVec3::splat(5),
        };
        assert_eq!(
            a.intersection(&b),
            Some(CellRange {
                min: IVec3::splat(3),
                max: IVec3::splat(3)
            })
        );
        assert!(a.intersection(&c).is_none() && !a.overlaps(&c));
        assert_eq!(
            a.union(&c),
            CellRange {
                min: IVec3::ZERO,
                max: IVec3::splat(5)
            }
        );
    }
}

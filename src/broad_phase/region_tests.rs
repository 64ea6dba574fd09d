//! Tests of a region's sweep ([`super::Region`]): cell ranges, the sort's budget, and sweeps of
//! few changed members against brute force.

use super::*;

#[test]
fn a_range_holds_the_cells_of_its_corners_and_counts_them() {
    let aabb = Aabb {
        min: glam::Vec3::new(-0.5, 0.0, 3.9),
        max: glam::Vec3::new(1.5, 0.9, 4.1),
    };
    let range = CellRange::of(&aabb, 1.0);
    assert_eq!(range.lo, [-1, 0, 3]);
    assert_eq!(range.hi, [1, 0, 4]);
    assert_eq!(range.count(), 6);
    assert_eq!(range.cells().count(), 6);
    assert!(range.cells().all(|c| range.contains(c)));
    let huge = Aabb {
        min: glam::Vec3::splat(-f32::MAX),
        max: glam::Vec3::splat(f32::MAX),
    };
    assert!(CellRange::of(&huge, 1.0).count() > 1 << 40);
}

#[test]
fn sort_entries_counts_swaps_and_falls_back_when_over_budget() {
    let entry = |lo: f32, owner: u32| Entry {
        lo,
        hi: lo,
        cross: [0.0; 4],
        owner: owner << 1,
        low_cell: [0; 3],
    };
    let mut nearly: Vec<Entry> = [0.0, 2.0, 1.0, 3.0]
        .iter()
        .zip(0..)
        .map(|(&lo, i)| entry(lo, i))
        .collect();
    assert_eq!(sort_entries(&mut nearly), 1);
    assert!(nearly.windows(2).all(|w| w[0].lo <= w[1].lo));
    let mut reversed: Vec<Entry> = (0..100).map(|i| entry(-(i as f32), i)).collect();
    let swaps = sort_entries(&mut reversed);
    assert!(swaps <= REGION_SWAP_BUDGET * 100 + 100, "{swaps}");
    assert!(reversed.windows(2).all(|w| w[0].lo <= w[1].lo));
}

/// Boxes inside the cell `[0, 8)³` (`None`: removed).
struct Boxes(Vec<Option<Aabb>>);

impl BodyView for Boxes {
    fn entry(&self, id: ProxyId, cell: [i32; 3], axes: [usize; 3]) -> Option<Entry> {
        let aabb = self.0[id as usize]?;
        let range = CellRange::of(&aabb, 1.0 / 8.0);
        range
            .contains(cell)
            .then(|| Entry::new(&aabb, id, false, &range, axes))
    }
    fn id_bound(&self) -> usize {
        self.0.len()
    }
}

fn brute_force(boxes: &[Option<Aabb>]) -> Vec<Pair> {
    let mut pairs = Vec::new();
    for (i, a) in boxes.iter().enumerate() {
        for (j, b) in boxes.iter().enumerate().skip(i + 1) {
            if let (Some(a), Some(b)) = (a, b)
                && a.intersects(b)
            {
                pairs.push(Pair::ordered(i as ProxyId, j as ProxyId));
            }
        }
    }
    pairs
}

/// Sweeps of two changed members among forty (moves, departures, arrivals, one repeated id),
/// every tenth step twenty (a full sweep between sweeps of few), keep exactly the brute-force
/// pairs and report exactly their changes; the entries stay sorted and unmarked.
#[test]
fn sweeps_of_few_and_full_sweeps_keep_exactly_the_brute_force_pairs_and_changes() {
    let mut seed = 0x9e37_79b9_u32;
    let mut unit = move || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    };
    let mut random_box = || {
        let min = glam::Vec3::new(unit(), unit(), unit()) * 7.0;
        Aabb {
            min,
            max: min + glam::Vec3::splat(0.3 + unit()),
        }
    };
    let mut view = Boxes((0..40).map(|_| Some(random_box())).collect());
    let mut region = Region::default();
    let frame = SweepFrame {
        axes: [0, 1, 2],
        inverse_size: 1.0 / 8.0,
    };
    let mut scratch = SweepScratch::default();
    let (mut added, mut removed) = (Vec::new(), Vec::new());
    let mut last: Vec<Pair> = Vec::new();
    region.changed.extend(0..40);
    for step in 0..300u32 {
        added.clear();
        removed.clear();
        region.sweep(&view, frame, &mut scratch, (&mut added, &mut removed));
        let mut owned = region.owned.clone();
        owned.sort_unstable();
        let now = brute_force(&view.0);
        assert_eq!(owned, now, "step {step}");
        added.sort_unstable();
        removed.sort_unstable();
        let new: Vec<Pair> = now.iter().filter(|p| !last.contains(p)).copied().collect();
        let gone: Vec<Pair> = last.iter().filter(|p| !now.contains(p)).copied().collect();
        assert_eq!((&added, &removed), (&new, &gone), "step {step}");
        last = now;
        assert!(region.entries.windows(2).all(|w| w[0].lo <= w[1].lo));
        assert!(region.entries.iter().all(|e| !e.is_fresh()));
        let first = step * 7 % 40;
        let ids: Vec<u32> = if step % 10 == 9 {
            (0..20).map(|k| (first + 2 * k) % 40).collect()
        } else {
            vec![first, (step * 13 + 1) % 40, first]
        };
        for id in ids {
            // Mostly small moves (towards the cell's middle, so no box drifts out), now and
            // then a departure or an arrival.
            let slot = &mut view.0[id as usize];
            *slot = match (step % 9, *slot) {
                (0, _) => None,
                (_, Some(b)) => {
                    let towards = b.min.cmplt(glam::Vec3::splat(3.5));
                    let shift = glam::Vec3::select(
                        towards,
                        glam::Vec3::splat(0.05),
                        glam::Vec3::splat(-0.05),
                    );
                    Some(Aabb {
                        min: b.min + shift,
                        max: b.max + shift,
                    })
                }
                (_, None) => Some(random_box()),
            };
            region.changed.push(id);
        }
    }
}

//! Which fast bodies may meet which other moving bodies in a substep: the candidates of
//! continuous collision between two moving bodies.
//!
//! The moving-body broad phase grows each box by the body's lookahead, capped at the body's
//! size, so a body crossing more than its size in a substep can meet a body the broad phase
//! never paired it with (two 10 cm balls closing at 20 m/s, a bullet and a plank). Rapier's CCD
//! finds those pairs in its broad phase by growing a CCD body's box by its predicted motion;
//! here the fast bodies are few and change every substep, so they get a sweep of their own:
//! the fast bodies' swept boxes against every moving body's box, by sort and sweep (the
//! slides' algorithm, from scratch: the set is rebuilt each substep), after dropping the boxes
//! that miss the union of the swept ones (in a game, most bodies are far from every bullet).
//! The sweep runs along the axis on which the swept boxes are shortest against the union's
//! extent ([`sweep_axis`]): bullets fired side by side along x are all open together along x,
//! and every box they pass was tested against each of them; across the volley each bullet
//! keeps to its own lane.
//! Only pairs with at least one fast body are reported: two slow bodies are the speculative
//! contacts' business.

use crate::bounding::Aabb;
use crate::broad_phase::float_order_key;

/// Reusable buffers of [`pairs_with_a_fast_body`].
#[derive(Debug, Default, Clone)]
pub struct MoverPairScratch {
    order: Vec<u64>,
    fast_open: Vec<u32>,
    slow_open: Vec<u32>,
}

/// The pairs `[i, j]` (`i < j`) of `boxes` that overlap and of which at least one is fast:
/// `boxes[..fast]` are the fast bodies' swept boxes, the rest the other moving bodies' boxes.
/// Appended to `out` (cleared first), sorted. Touching boxes overlap (closed intervals, as
/// [`Aabb::intersects`]). Boxes with a NaN bound meet nothing.
pub fn pairs_with_a_fast_body(
    boxes: &[Aabb],
    fast: usize,
    scratch: &mut MoverPairScratch,
    out: &mut Vec<[u32; 2]>,
) {
    out.clear();
    let fast = fast.min(boxes.len());
    if fast == 0 {
        return;
    }
    let reach = boxes[..fast]
        .iter()
        .fold(Aabb::EMPTY, |union, b| union.union(b));
    let axis = sweep_axis(&boxes[..fast], &reach);
    // Sorted by the start along the axis (as integer keys, the box's index below), boxes that
    // can meet no swept one and boxes with a NaN left out. Box indices fit in u32: callers
    // index bodies by u32 (the broad phase's proxy ids).
    let order = &mut scratch.order;
    order.clear();
    order.extend((0..boxes.len() as u32).filter_map(|i| {
        let b = &boxes[i as usize];
        let kept = b.is_valid() && ((i as usize) < fast || b.intersects(&reach));
        kept.then(|| u64::from(float_order_key(b.min[axis])) << 32 | u64::from(i))
    }));
    order.sort_unstable();
    // The boxes whose interval is still open, fast and slow apart: a slow box is tested
    // against the fast ones only, and the slow list is pruned and read only when a fast box
    // comes (in a dense pile a slow box overlaps a hundred others along the axis).
    let (fast_open, slow_open) = (&mut scratch.fast_open, &mut scratch.slow_open);
    fast_open.clear();
    slow_open.clear();
    for &key in order.iter() {
        let i = key as u32;
        let b = &boxes[i as usize];
        let mut meet = |j: u32| {
            if b.intersects(&boxes[j as usize]) {
                out.push([i.min(j), i.max(j)]);
            }
        };
        // Boxes whose interval ended before this one starts can meet nothing later.
        let open = |j: &u32| boxes[*j as usize].max[axis] >= b.min[axis];
        fast_open.retain(open);
        fast_open.iter().for_each(|&j| meet(j));
        if (i as usize) < fast {
            slow_open.retain(open);
            slow_open.iter().for_each(|&j| meet(j));
            fast_open.push(i);
        } else {
            slow_open.push(i);
        }
    }
    out.sort_unstable();
}

/// The axis along which the `swept` boxes (whose union is `reach`) are open over the least of
/// the union: per axis, the sum of their extents over the union's, the number of swept boxes
/// a box inside the union finds open on average. Ties (one swept box, a cube of them) keep the
/// lowest axis; an axis on which the union is flat counts every swept box as open.
fn sweep_axis(swept: &[Aabb], reach: &Aabb) -> usize {
    let spread = reach.max - reach.min;
    let open = |axis: usize| -> f32 {
        let total: f32 = swept.iter().map(|b| b.max[axis] - b.min[axis]).sum();
        if spread[axis] > 0.0 {
            total / spread[axis]
        } else {
            swept.len() as f32
        }
    };
    let costs = [open(0), open(1), open(2)];
    // `<` keeps the lower axis on a tie and never picks a NaN cost.
    (1..3).fold(0, |best, a| if costs[a] < costs[best] { a } else { best })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::TestRng as Rng;
    use glam::Vec3;

    fn brute_force(boxes: &[Aabb], fast: usize) -> Vec<[u32; 2]> {
        let mut out = Vec::new();
        for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                if (i < fast || j < fast) && boxes[i].intersects(&boxes[j]) {
                    out.push([i as u32, j as u32]);
                }
            }
        }
        out
    }

    fn random_box(rng: &mut Rng, spread: f32, size: f32) -> Aabb {
        let c = rng.vec3(-spread, spread);
        let h = rng.vec3(0.0, size);
        Aabb::new(c - h, c + h)
    }

    /// Random scenes of long swept boxes among small ones, coincident and touching boxes
    /// included: exactly brute force's pairs (fails if a pair of two slow bodies is let in, if
    /// the union filter drops a box that meets a swept one, or if a closed interval is opened).
    #[test]
    fn finds_exactly_brute_forces_pairs_with_a_fast_body() {
        let mut rng = Rng::new(7);
        let (mut scratch, mut out) = (MoverPairScratch::default(), Vec::new());
        for round in 0..300 {
            let n = 1 + round % 60;
            let fast = round % 7;
            let mut boxes: Vec<Aabb> = (0..n)
                .map(|k| {
                    let size = if k < fast { 4.0 } else { 0.6 };
                    random_box(&mut rng, 6.0, size)
                })
                .collect();
            if n > 3 {
                // A coincident pair and one touching another face to face.
                boxes[n - 1] = boxes[0];
                let b = boxes[1];
                let shift = Vec3::X * (b.max.x - b.min.x);
                boxes[n - 2] = Aabb::new(b.min + shift, b.max + shift);
            }
            pairs_with_a_fast_body(&boxes, fast, &mut scratch, &mut out);
            assert_eq!(out, brute_force(&boxes, fast.min(n)), "round {round}");
        }
    }

    /// A volley of 25 bullets fired along x side by side, each swept 5 m through a lane of
    /// boxes, sweeps across the volley (not along x, where all 25 are open together), and
    /// finds exactly brute force's pairs; fired along z, it sweeps across too.
    #[test]
    fn a_volley_sweeps_across_its_lanes_and_finds_exactly_brute_forces_pairs() {
        let (mut scratch, mut out) = (MoverPairScratch::default(), Vec::new());
        for along in [0usize, 2] {
            let lane = |k: usize, t: f32| {
                let mut v = Vec3::ZERO;
                v[along] = t;
                v[(along + 1) % 3] = (k % 5) as f32;
                v[(along + 2) % 3] = (k / 5) as f32;
                v
            };
            let (mut boxes, half) = (Vec::new(), Vec3::splat(0.2));
            for k in 0..25 {
                let (start, end) = (lane(k, 0.0), lane(k, 5.0));
                boxes.push(Aabb::new(start.min(end) - 0.01, start.max(end) + 0.01));
            }
            for k in 0..25 {
                for t in 0..8 {
                    let c = lane(k, 1.0 + t as f32);
                    boxes.push(Aabb::new(c - half, c + half));
                }
            }
            let axis = sweep_axis(
                &boxes[..25],
                &boxes[..25].iter().fold(Aabb::EMPTY, |u, b| u.union(b)),
            );
            assert_ne!(axis, along);
            pairs_with_a_fast_body(&boxes, 25, &mut scratch, &mut out);
            let expected = brute_force(&boxes, 25);
            assert_eq!(out, expected);
            assert!(expected.len() >= 25 * 5, "{} pairs", expected.len());
        }
    }

    #[test]
    fn no_fast_body_no_pair_and_a_nan_box_meets_nothing() {
        let unit = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let (mut scratch, mut out) = (MoverPairScratch::default(), vec![[9, 9]]);
        pairs_with_a_fast_body(&[unit, unit], 0, &mut scratch, &mut out);
        assert!(out.is_empty());
        let nan = Aabb::new(Vec3::splat(f32::NAN), Vec3::ONE);
        pairs_with_a_fast_body(&[nan, unit, unit], 1, &mut scratch, &mut out);
        assert!(out.is_empty());
        pairs_with_a_fast_body(&[unit, nan, unit], 1, &mut scratch, &mut out);
        assert_eq!(out, vec![[0, 2]]);
    }
}

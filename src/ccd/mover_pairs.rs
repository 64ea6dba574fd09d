//! Which fast bodies may meet which other moving bodies in a substep: the candidates of
//! continuous collision between two moving bodies.
//!
//! The moving-body broad phase grows each box by the body's lookahead, capped at the body's
//! size, so a body crossing more than its size in a substep can meet a body the broad phase
//! never paired it with (two 10 cm balls closing at 20 m/s, a bullet and a plank). Rapier's CCD
//! finds those pairs in its broad phase by growing a CCD body's box by its predicted motion;
//! here the fast bodies are few and change every substep, so they get a sweep of their own:
//! the fast bodies' swept boxes against every moving body's box, by sort and sweep along x (the
//! slides' algorithm, from scratch: the set is rebuilt each substep), after dropping the boxes
//! that miss the union of the swept ones (in a game, most bodies are far from every bullet).
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
    // Sorted by the start along x (as integer keys, the box's index below), boxes that can
    // meet no swept one and boxes with a NaN left out. Box indices fit in u32: callers index
    // bodies by u32 (the broad phase's proxy ids).
    let order = &mut scratch.order;
    order.clear();
    order.extend((0..boxes.len() as u32).filter_map(|i| {
        let b = &boxes[i as usize];
        let kept = b.is_valid() && ((i as usize) < fast || b.intersects(&reach));
        kept.then(|| u64::from(float_order_key(b.min.x)) << 32 | u64::from(i))
    }));
    order.sort_unstable();
    // The boxes whose x interval is still open, fast and slow apart: a slow box is tested
    // against the fast ones only, and the slow list is pruned and read only when a fast box
    // comes (in a dense pile a slow box overlaps a hundred others along x).
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
        // Boxes whose x interval ended before this one starts can meet nothing later.
        let open = |j: &u32| boxes[*j as usize].max.x >= b.min.x;
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

//! Endpoint identities and positions: the owner word of an endpoint, the positions each body
//! records for its six endpoints, and the overlap tests on positions.
//!
//! The slides' observation: every adjacent transposition of a min and a max of two bodies
//! starts or ends the overlap of their projections on that axis, and nothing else does. So two
//! bodies overlap on an axis iff, by *position*, each min precedes the other's max; comparing
//! positions (Bullet's `testOverlap2D`) rather than values keeps this exact while other bodies'
//! endpoints are still on their way. The tests here are written without branches: on random
//! scenes each comparison is a coin toss, and mispredicted branches made the swap loop twice
//! as slow.

use super::ProxyId;

/// Owner-word flag: the endpoint is a max.
pub const MAX_FLAG: u32 = 1;
/// Owner-word flag: the body is static.
const STATIC_FLAG: u32 = 2;

/// Positions of a body's endpoints: index `axis * 2` for the min, `axis * 2 + 1` for the max.
pub type EndpointSlots = [u32; 6];

/// The owner word of an endpoint.
#[inline]
pub fn owner_word(id: ProxyId, is_static: bool, is_max: bool) -> u32 {
    id << 2 | u32::from(is_static) << 1 | u32::from(is_max)
}

/// The body owning an endpoint.
#[inline]
pub fn owner_id(owner: u32) -> ProxyId {
    owner >> 2
}

/// Whether both owner words belong to static bodies (their pair is never tracked).
#[inline]
pub fn both_static(o1: u32, o2: u32) -> bool {
    o1 & o2 & STATIC_FLAG != 0
}

/// Where an endpoint's position lives in its body's [`EndpointSlots`].
#[inline]
pub fn slot_index(axis: usize, owner: u32) -> usize {
    axis * 2 + (owner & MAX_FLAG) as usize
}

/// A body's endpoint positions on the two axes other than one: `[min_u, max_u, min_v, max_v]`.
pub type CrossSlots = [u32; 4];

/// The two axes other than `axis`.
#[inline]
pub fn other_axes(axis: usize) -> (usize, usize) {
    match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// A body's positions on the axes other than `axis`.
#[inline]
pub fn cross_slots(s: &EndpointSlots, axis: usize) -> CrossSlots {
    let (u, v) = other_axes(axis);
    [s[2 * u], s[2 * u + 1], s[2 * v], s[2 * v + 1]]
}

/// Whether two bodies overlap by position on both of their cross axes (Bullet's
/// `testOverlap2D`).
#[inline]
pub fn cross_overlap(s: &CrossSlots, t: &CrossSlots) -> bool {
    cross_overlap_bit(s, t) != 0
}

/// [`cross_overlap`] as a 0/1 integer computed without compares: positions are below 2^31,
/// so `a < b` is the sign bit of `a - b`. Compilers turn a chain of compares into a chain of
/// branches, and on random data each of them is a coin toss.
#[inline(always)]
pub fn cross_overlap_bit(s: &CrossSlots, t: &CrossSlots) -> u32 {
    let below = |a: u32, b: u32| a.wrapping_sub(b);
    (below(s[0], t[1]) & below(t[0], s[1]) & below(s[2], t[3]) & below(t[2], s[3])) >> 31
}

/// One endpoint passing another while an axis is being sorted.
#[derive(Clone, Copy, Debug)]
pub struct Pass {
    /// The axis being sorted.
    pub axis: usize,
    /// Owner word of the travelling endpoint.
    pub moving: u32,
    /// Owner word of the endpoint it passed.
    pub passed: u32,
    /// Whether the travelling endpoint moves towards the front.
    pub moving_down: bool,
    /// The travelling body's positions on the other axes (unchanged while this axis sorts).
    pub moving_cross: CrossSlots,
}

impl Pass {
    /// Whether the pass flips the two bodies' overlap on this axis: a min and a max of two
    /// bodies that are not both static.
    #[inline(always)]
    pub fn flips_overlap(&self) -> bool {
        self.flips_overlap_bit() != 0
    }

    /// [`Pass::flips_overlap`] as a 0/1 integer, without branches.
    #[inline(always)]
    pub fn flips_overlap_bit(&self) -> u32 {
        let (m, p) = (self.moving, self.passed);
        (m ^ p) & !((m & p & STATIC_FLAG) >> 1) & MAX_FLAG
    }

    /// For a flipping pass, whether the overlap begins (down: a min passing a max; up: a max
    /// passing a min) rather than ends.
    #[inline(always)]
    pub fn begins(&self) -> bool {
        (self.moving & MAX_FLAG == 0) == self.moving_down
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn branch_free_cross_overlap_matches_the_comparisons() {
        let big = (1u32 << 31) - 1;
        let values = [0, 1, 2, 3, big - 1, big];
        let compared = |s: &CrossSlots, t: &CrossSlots| {
            s[0] < t[1] && t[0] < s[1] && s[2] < t[3] && t[2] < s[3]
        };
        for &a in &values {
            for &b in &values {
                for &c in &values {
                    for &d in &values {
                        let s = [a, b, 1, 2];
                        let t = [c, d, 0, 3];
                        assert_eq!(cross_overlap(&s, &t), compared(&s, &t), "{s:?} {t:?}");
                        let s = [1, 2, a, b];
                        let t = [0, 3, c, d];
                        assert_eq!(cross_overlap(&s, &t), compared(&s, &t), "{s:?} {t:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn passes_flip_only_between_a_min_and_a_max_of_a_non_static_pair() {
        for moving_static in [false, true] {
            for passed_static in [false, true] {
                for moving_max in [false, true] {
                    for passed_max in [false, true] {
                        for moving_down in [false, true] {
                            let pass = Pass {
                                axis: 0,
                                moving: owner_word(3, moving_static, moving_max),
                                passed: owner_word(7, passed_static, passed_max),
                                moving_down,
                                moving_cross: [0; 4],
                            };
                            let flips =
                                moving_max != passed_max && !(moving_static && passed_static);
                            assert_eq!(pass.flips_overlap(), flips, "{pass:?}");
                            if flips {
                                // Down: a min passing a max starts the overlap; up: a max passing a min.
                                assert_eq!(pass.begins(), moving_down != moving_max, "{pass:?}");
                            }
                        }
                    }
                }
            }
        }
    }
}

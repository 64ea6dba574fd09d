//! Collision layers: which colliders may touch, as bit masks (Avian's `CollisionLayers`,
//! rapier's `InteractionGroups`).
//!
//! A collider is a *member* of some of 32 layers and *filters* the layers it interacts with.
//! Two colliders interact when each is a member of a layer the other filters:
//! `(a.memberships & b.filters) != 0 && (b.memberships & a.filters) != 0`, so either side can
//! refuse the other (a ghost filtering nothing passes through everything, whatever the wall
//! says). The default is Avian's: a member of the first layer, filtering every layer, so
//! colliders without layers interact with everything that has not opted out of layer 0.
//!
//! Queries (ray casts, overlaps) use only the filter side: a query with mask `m` sees the
//! colliders with `memberships & m != 0`.

use std::ops::{BitAnd, BitOr, Not};

/// A set of the 32 layers, one bit each.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LayerMask(pub u32);

impl LayerMask {
    /// No layer.
    pub const NONE: Self = Self(0);
    /// Every layer.
    pub const ALL: Self = Self(u32::MAX);
    /// The first layer, where colliders are by default.
    pub const DEFAULT: Self = Self(1);

    /// The single layer `index` (0 to 31); `None` beyond.
    pub const fn layer(index: u32) -> Option<Self> {
        if index < 32 {
            Some(Self(1 << index))
        } else {
            None
        }
    }

    /// Whether the two sets share a layer.
    pub const fn intersects(self, other: Self) -> bool {
        self.0 & other.0 != 0
    }
}

impl Default for LayerMask {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl BitOr for LayerMask {
    type Output = Self;
    fn bitor(self, rhs: Self) -> Self {
        Self(self.0 | rhs.0)
    }
}

impl BitAnd for LayerMask {
    type Output = Self;
    fn bitand(self, rhs: Self) -> Self {
        Self(self.0 & rhs.0)
    }
}

impl Not for LayerMask {
    type Output = Self;
    fn not(self) -> Self {
        Self(!self.0)
    }
}

/// The layers a collider is in and the layers it interacts with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Layers {
    /// The layers the collider is in.
    pub memberships: LayerMask,
    /// The layers it interacts with.
    pub filters: LayerMask,
}

impl Default for Layers {
    fn default() -> Self {
        Self {
            memberships: LayerMask::DEFAULT,
            filters: LayerMask::ALL,
        }
    }
}

impl Layers {
    /// In every layer, interacting with every layer.
    pub const ALL: Self = Self {
        memberships: LayerMask::ALL,
        filters: LayerMask::ALL,
    };
    /// In no layer, interacting with nothing.
    pub const NONE: Self = Self {
        memberships: LayerMask::NONE,
        filters: LayerMask::NONE,
    };

    /// Members of `memberships`, interacting with `filters`.
    pub const fn new(memberships: LayerMask, filters: LayerMask) -> Self {
        Self {
            memberships,
            filters,
        }
    }

    /// Whether two colliders with these layers may touch (each accepts the other).
    pub const fn interacts_with(&self, other: &Self) -> bool {
        self.memberships.intersects(other.filters) && other.memberships.intersects(self.filters)
    }

    /// Whether no layers at all interact with these (no membership, or no filter): a collider
    /// with them touches nothing, so the broad phase need not keep it.
    pub const fn interact_with_none(&self) -> bool {
        self.memberships.0 == 0 || self.filters.0 == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interaction_needs_both_sides_to_accept_on_every_mask_pair_of_3_bits() {
        let masks = (0..8).map(LayerMask);
        for am in masks.clone() {
            for af in masks.clone() {
                for bm in masks.clone() {
                    for bf in masks.clone() {
                        let (a, b) = (Layers::new(am, af), Layers::new(bm, bf));
                        let expected = (am.0 & bf.0 != 0) && (bm.0 & af.0 != 0);
                        assert_eq!(a.interacts_with(&b), expected);
                        assert_eq!(a.interacts_with(&b), b.interacts_with(&a));
                    }
                }
            }
        }
    }

    #[test]
    fn layers_interact_with_none_iff_no_layers_of_3_bits_interact_with_them() {
        let all =
            || (0..8).flat_map(|m| (0..8).map(move |f| Layers::new(LayerMask(m), LayerMask(f))));
        for a in all() {
            let some = all().any(|b| a.interacts_with(&b));
            assert_eq!(a.interact_with_none(), !some, "{a:?}");
        }
    }

    #[test]
    fn default_layers_interact_and_layer_32_is_refused() {
        assert!(Layers::default().interacts_with(&Layers::default()));
        assert!(!Layers::NONE.interacts_with(&Layers::ALL));
        assert_eq!(LayerMask::layer(31), Some(LayerMask(1 << 31)));
        assert_eq!(LayerMask::layer(32), None);
    }
}

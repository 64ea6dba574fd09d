//! Impulses kept from one step to the next (warm starting across steps; Catto, GDC 2005 and
//! Box2D v3's `b2StoreImpulses`).
//!
//! A resting stack needs the same impulses every step; starting each step from zero would make
//! the substeps rebuild the support of every box from scratch. The impulses of each contact are
//! kept under the caller's pair key, in key order (a merge, never a hash: the same input gives
//! the same result on every run), with each point's anchor in A's body frame and its feature id.
//! A new point takes the impulses of the old point of the same pair made by the same features
//! ([`FeatureId`]: Box2D's and rapier's rule), wherever it has
//! moved; a point no feature names, or whose features are new, takes those of the nearest old
//! point within `match_distance` (the persistent-manifold rule of Bullet and Jolt). The
//! friction impulse is kept as a world vector and projected on the new tangents. Under friction
//! per patch the contact's one friction impulse and its twist are kept the same way, by key.
//!
//! Why ids as well as places: the anchors are kept in A's frame, and a box sliding or spinning
//! on the ground (the ground its A) moves its corners across that frame, past the match
//! distance at 3 m/s: every step began its points from nothing. A plate spun at 10 rad/s on the
//! ground then sank 0.13 mm deeper than when spawned before the ground (its corners fixed in
//! A's frame), and a cube sliding at 10 m/s 15 µm: the same scene, two answers by spawn order.
//!
//! A rounded side (a ball, a capsule: [`ContactConstraint::rounding`]) rolls its contact over
//! its surface and across the other body, 5 cm a step at 3 m/s: its points are matched by its
//! core point (`r ∓ ρ n`, in its own frame), which rolling does not move. A ball rolling
//! faster than 3 m/s lost its warm start every step, and on a turntable its friction then
//! lagged a substep behind and let it drift outward (0.9 mm/s at 2.5 m and 2 rad/s).

use super::contact::{ConstraintPoint, ContactConstraint};
use crate::geometry::{FeatureId, MAX_MANIFOLD_POINTS};
use glam::{Quat, Vec3};

/// One point's impulses.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct StoredPoint {
    /// Anchor in A's body frame.
    local_anchor: Vec3,
    /// The features that made it.
    feature: FeatureId,
    normal_impulse: f32,
    friction_impulse: Vec3,
}

/// One contact's impulses.
#[derive(Clone, Copy, Debug, PartialEq)]
struct StoredContact {
    key: u128,
    points: [StoredPoint; MAX_MANIFOLD_POINTS],
    count: u8,
    /// The patch's friction impulse (world) and twist impulse, under friction per patch.
    patch: Option<(Vec3, f32)>,
}

/// The impulses of the last step, by pair key.
#[derive(Clone, Debug, Default)]
pub struct WarmStartCache {
    contacts: Vec<StoredContact>,
    /// Substep length they were computed with (impulses scale with it).
    h: f32,
}

impl WarmStartCache {
    /// Number of contacts remembered.
    pub fn len(&self) -> usize {
        self.contacts.len()
    }

    /// True when nothing is remembered.
    pub fn is_empty(&self) -> bool {
        self.contacts.is_empty()
    }

    /// Forgets everything.
    pub fn clear(&mut self) {
        self.contacts.clear();
    }

    /// Seeds `constraints` (sorted by key) with the remembered impulses; `orientation` gives
    /// each body's orientation (by slot) at the step's start.
    pub fn seed(
        &self,
        constraints: &mut [ContactConstraint],
        orientation: impl Fn(u32) -> Quat,
        h: f32,
        match_distance: f32,
    ) {
        if self.contacts.is_empty() || self.h <= 0.0 {
            return;
        }
        let scale = h / self.h;
        let mut cursor = 0;
        for c in constraints.iter_mut() {
            while cursor < self.contacts.len() && self.contacts[cursor].key < c.key {
                cursor += 1;
            }
            let Some(old) = self.contacts.get(cursor).filter(|o| o.key == c.key) else {
                continue;
            };
            let old_points = &old.points[..old.count as usize];
            let side = MatchedSide::of(c, &orientation);
            seed_points(c, old_points, &side, (scale, match_distance));
            let (normal, tangents) = (c.normal, c.tangents);
            if c.friction == 0.0 {
                // Friction switched off since the last step: its rows are not solved, so a
                // kept impulse would never be bounded again (a box sliding at 2.55 m/s whose
                // friction was set to 0 accelerated backwards at μ g for ever).
                continue;
            }
            if let (Some(patch), Some((f, twist))) = (&mut c.patch, old.patch) {
                patch.tangent_impulse = on_tangents(f, normal, tangents, scale);
                patch.twist_impulse = twist * scale;
            }
        }
    }

    /// Remembers the impulses of `constraints` (sorted by key), replacing the last step's;
    /// `orientation` as in [`Self::seed`].
    pub fn store(
        &mut self,
        constraints: &[ContactConstraint],
        orientation: impl Fn(u32) -> Quat,
        h: f32,
    ) {
        self.contacts.clear();
        self.h = h;
        for c in constraints {
            let points = stored_points(c, &MatchedSide::of(c, &orientation));
            let patch = c
                .patch
                .map(|p| (in_world(c.tangents, p.tangent_impulse), p.twist_impulse));
            self.contacts.push(StoredContact {
                key: c.key,
                points,
                count: c.count,
                patch,
            });
        }
    }
}

/// Seeds the points of `c` from the `old` ones of its pair: each takes the impulses of the old
/// point made by the same features, else of the nearest old point whose place (in the matched
/// `side`'s frame) lies within the match distance, scaled by the substeps' ratio.
fn seed_points(
    c: &mut ContactConstraint,
    old: &[StoredPoint],
    side: &MatchedSide,
    (scale, match_distance): (f32, f32),
) {
    let (normal, tangents) = (c.normal, c.tangents);
    // An old point seeds one new point by its features (a mesh may report one feature twice,
    // a box's corner over a seam from both triangles).
    let mut taken = 0u8;
    for cp in &mut c.points[..c.count as usize] {
        let same = old.iter().enumerate().find(|(k, p)| {
            cp.feature.is_some() && p.feature == cp.feature && taken & (1 << k) == 0
        });
        if let Some((k, _)) = same {
            taken |= 1 << k;
        }
        let matched = same.map(|(_, p)| p).or_else(|| {
            let local = side.local(cp);
            let nearest = old
                .iter()
                .map(|p| (p.local_anchor.distance_squared(local), p))
                .min_by(|x, y| x.0.total_cmp(&y.0));
            let close = nearest.filter(|(d2, _)| *d2 <= match_distance * match_distance);
            close.map(|(_, p)| p)
        });
        if let Some(p) = matched {
            cp.normal_impulse = p.normal_impulse.max(0.0) * scale;
            cp.max_normal_impulse = cp.normal_impulse;
            if c.friction > 0.0 {
                cp.tangent_impulse = on_tangents(p.friction_impulse, normal, tangents, scale);
            }
        }
    }
}

/// The points of `c` to remember, each at its place in the matched `side`'s frame.
fn stored_points(c: &ContactConstraint, side: &MatchedSide) -> [StoredPoint; MAX_MANIFOLD_POINTS] {
    let mut points = [StoredPoint::default(); MAX_MANIFOLD_POINTS];
    for (stored, cp) in points.iter_mut().zip(c.points()) {
        *stored = StoredPoint {
            local_anchor: side.local(cp),
            feature: cp.feature,
            normal_impulse: cp.normal_impulse,
            friction_impulse: in_world(c.tangents, cp.tangent_impulse),
        };
    }
    points
}

/// The side whose frame a contact's points are matched in: a rounded side, at its points'
/// cores (module docs), else A at its anchors.
struct MatchedSide {
    /// From world axes to the side's body frame (at the step's start).
    to_local: Quat,
    /// B (else A).
    b: bool,
    /// From the anchor to the core point along the normal (zero on a side with corners).
    to_core: Vec3,
}

impl MatchedSide {
    /// A's side if A is rounded, else B's if B is; A's anchors without rounding.
    /// `orientation` gives each body's orientation by slot.
    fn of(c: &ContactConstraint, orientation: &impl Fn(u32) -> Quat) -> Self {
        let [rho_a, rho_b] = c.rounding;
        let b = rho_a <= 0.0 && rho_b > 0.0;
        let (slot, to_core) = if b {
            (c.b, c.normal * rho_b)
        } else if rho_a > 0.0 {
            (c.a, -c.normal * rho_a)
        } else {
            (c.a, Vec3::ZERO)
        };
        Self {
            to_local: orientation(slot).inverse(),
            b,
            to_core,
        }
    }

    /// Point `cp`'s place in the side's frame: its core point, or A's anchor.
    fn local(&self, cp: &ConstraintPoint) -> Vec3 {
        let anchor = if self.b { cp.anchor_b } else { cp.anchor_a };
        self.to_local * (anchor + self.to_core)
    }
}

/// A friction impulse kept as a world vector, on the new `tangents` (its part along the new
/// `normal` dropped), scaled by the substeps' ratio.
fn on_tangents(f: Vec3, normal: Vec3, tangents: [Vec3; 2], scale: f32) -> [f32; 2] {
    let f = f - normal * f.dot(normal);
    tangents.map(|t| f.dot(t) * scale)
}

/// A friction impulse along `tangents` as a world vector.
fn in_world(tangents: [Vec3; 2], [f0, f1]: [f32; 2]) -> Vec3 {
    tangents[0] * f0 + tangents[1] * f1
}

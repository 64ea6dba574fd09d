//! Reusing a pair's contact while its two shapes have barely moved relative to each other:
//! Jolt's body pair cache (`PhysicsSettings::mBodyPairCacheMaxDeltaPositionSq`, 1 mm), here
//! for the pairs whose test is costly (a mesh against anything: hundreds of triangle pairs; two
//! boxes: axes, clipping and the choice of four points; the GJK/EPA shapes).
//!
//! An entry keeps B's pose in A's frame at the time of the test and the manifold in A's frame
//! (or that the shapes were apart). While B has since moved, in A's frame, by less than
//! [`MAX_SHIFT`] at any point of its reach, the entry answers instead of the test: its points are
//! carried back to the world by A's pose now, and each depth is corrected by how far B's
//! surface moved along the normal at that point (exact for a translation, first order for a
//! turn), so the error stays below [`MAX_SHIFT`] however long the pair rests. A test looks
//! ahead by a margin (the speculative contacts'); an entry answers only while the margin asked
//! for is no more than [`MAX_SHIFT`] longer than the one it was tested with, so a pair at rest
//! whose body is suddenly thrown (a longer margin) is tested again; a pair tested with a longer
//! margin than it now asks for keeps the farther speculative points that test found (harmless
//! to the solver: a point apart only bounds the approach) until it moves. Entries not asked for
//! during a step are dropped at the start of the next.
//!
//! A round body rolling on a flat one is followed as it rolls ([`RoundSide`]). Kept in A's
//! frame, with its points midway between the two bodies' points, an entry turned with whichever
//! body was A: a ball, capsule or cylinder rolling on a box had its normal tilted forward (as
//! A) or its points left behind its centre (as B) by the angle it rolled since the test, and
//! the floor's push there spun it on: a log rolling at 2 mm/s on a box reached 2 cm/s in 10 s. Now B's turn in A's
//! frame is split into its twist about the normal and the swing that tilts the normal (the
//! swing–twist decomposition): the normal turns with the flat body, and the points ride with
//! the round body's centre and its twist about the normal (a turning capsule carries its ends
//! round), never with its roll.

use crate::geometry::{ContactManifold, ContactPoint, Isometry, Shape};
use crate::pair_hash::PairHashBuilder;
use glam::{Quat, Vec3};
use std::collections::HashMap;

/// Largest motion of B relative to A, at its reach, for which an entry is reused (m).
pub const MAX_SHIFT: f32 = 1e-3;

/// Which body of a pair is round against a flat other, if one is: how an entry follows the
/// bodies' motion since the test (the module notes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RoundSide {
    /// Neither is (two flat bodies meet on a face of either, two round ones along the line
    /// between them): the normal turns with A, the points are midway between the bodies'.
    Neither,
    /// A is round, B flat.
    A,
    /// B is round, A flat.
    B,
}

impl RoundSide {
    /// The round side of shapes `a` and `b` (a ball, capsule, cylinder or cone against a box,
    /// a hull, a mesh or a half-space; an ellipsoid's pairs are not kept, see the narrow
    /// phase's `worth_caching`).
    pub fn of(a: &Shape, b: &Shape) -> Self {
        match (is_round(a), is_round(b)) {
            (true, false) => Self::A,
            (false, true) => Self::B,
            _ => Self::Neither,
        }
    }
}

/// Shapes whose surface turns under a contact as they roll.
fn is_round(shape: &Shape) -> bool {
    matches!(
        shape,
        Shape::Sphere(_) | Shape::Capsule(_) | Shape::Cylinder(_) | Shape::Cone(_)
    )
}

/// The unit rotation `q` split as `swing · twist`, `twist` about the unit `axis` and `swing`
/// the part that tilts `axis`.
fn swing_twist(q: Quat, axis: Vec3) -> (Quat, Quat) {
    let along = axis * q.xyz().dot(axis);
    let twist = Quat::from_xyzw(along.x, along.y, along.z, q.w);
    let length = twist.length();
    if length > 0.0 {
        let twist = twist * length.recip();
        (q * twist.inverse(), twist)
    } else {
        // No twist (a half turn about an axis across `axis`, or NaN): all swing.
        (q, Quat::IDENTITY)
    }
}

/// The manifold `local` (A's frame, at the test) now: its normal `normal` (A's frame), each
/// point where `point` puts it given its place at the test and the motion since of B's point
/// there (`since`), each depth less that motion along the test's normal, all in the world by
/// A's pose.
fn carried(
    local: &ContactManifold,
    since: &Isometry,
    pose_a: &Isometry,
    normal: Vec3,
    point: impl Fn(Vec3, Vec3) -> Vec3,
) -> ContactManifold {
    let mut now = ContactManifold::new(pose_a.transform_vector(normal));
    for p in local.points() {
        // Where the point of B that was at `p` at the test is now (A's frame).
        let motion = since.transform_point(p.point) - p.point;
        now.push(ContactPoint {
            point: pose_a.transform_point(point(p.point, motion)),
            depth: p.depth - motion.dot(local.normal),
            ..*p
        });
    }
    now
}

#[derive(Debug, Clone)]
struct Entry {
    b_in_a: Isometry,
    /// Which body, if either, rolls on the other.
    round: RoundSide,
    /// How far ahead the test looked (m).
    margin: f32,
    /// The manifold in A's frame, or `None` for shapes that were apart.
    manifold: Option<ContactManifold>,
    /// The triangle pairs the test found (kept only when the caller records them).
    hits: Vec<[u32; 2]>,
    /// The step it was last asked for.
    used: u64,
}

/// The cached contacts of shape pairs, keyed by the caller (two collider ids, in test order).
#[derive(Debug, Default, Clone)]
pub struct ManifoldCache {
    entries: HashMap<(u64, u64), Entry, PairHashBuilder>,
    step: u64,
    hits: u64,
}

impl ManifoldCache {
    /// Starts a step: drops the entries nobody asked for during the last one.
    pub fn begin_step(&mut self) {
        let last = self.step;
        self.entries.retain(|_, e| e.used >= last);
        self.step += 1;
    }

    /// The cached contact of pair `key` looking `margin` ahead if B (at `pose_b`, reaching
    /// `reach_b` from its origin) moved less than [`MAX_SHIFT`] relative to A (at `pose_a`)
    /// since it was stored: `Some(m)` with `m` the contact now (`None` inside: the shapes are
    /// apart), or `None` when the pair must be tested.
    pub fn get(
        &mut self,
        key: (u64, u64),
        (pose_a, pose_b): (&Isometry, &Isometry),
        reach_b: f32,
        margin: f32,
    ) -> Option<Option<ContactManifold>> {
        let step = self.step;
        let entry = self.entries.get_mut(&key)?;
        // A NaN margin is never answered (it compares as neither).
        let within = margin <= entry.margin + MAX_SHIFT;
        if !within {
            return None;
        }
        let b_in_a = pose_a.inv_mul(pose_b);
        let moved = b_in_a.translation - entry.b_in_a.translation;
        // The turn's angle from its quaternion's vector part (`2 asin |v|`): precise for the small
        // turns that matter here, where `acos` of the dot product is not.
        let delta = b_in_a.rotation * entry.b_in_a.rotation.inverse();
        let turned = 2.0 * delta.xyz().length().min(1.0).asin();
        // A reach that is no length (NaN, negative) cannot bound the motion: never a hit.
        let reach = if reach_b >= 0.0 { reach_b } else { f32::NAN };
        let shift = moved.length() + turned * reach;
        if shift.is_nan() || shift >= MAX_SHIFT {
            return None;
        }
        entry.used = step;
        self.hits += 1;
        let Some(local) = &entry.manifold else {
            return Some(None);
        };
        // B's motion in A's frame since the test: `b_in_a ∘ tested⁻¹`, whose turn is `delta`.
        let since = Isometry::new(b_in_a.translation - delta * entry.b_in_a.translation, delta);
        // One loop per round side (no choice per point); two flat bodies (most entries: box
        // pairs) need no split of the turn.
        let now = match entry.round {
            // Midway between the bodies' points.
            RoundSide::Neither => carried(local, &since, pose_a, local.normal, |p, motion| {
                p + motion * 0.5
            }),
            // Where round A now faces B's tilted face.
            RoundSide::A => {
                let (swing, _) = swing_twist(delta, local.normal);
                carried(local, &since, pose_a, swing * local.normal, |p, _| {
                    swing * p
                })
            }
            // Round B's point, carried by its centre and its twist (A's frame).
            RoundSide::B => {
                let (_, twist) = swing_twist(delta, local.normal);
                let (then, centre) = (entry.b_in_a.translation, b_in_a.translation);
                carried(local, &since, pose_a, local.normal, |p, _| {
                    centre + twist * (p - then)
                })
            }
        };
        Some(Some(now))
    }

    /// Stores the contact of pair `key` just tested (world frame) looking `margin` ahead, for
    /// [`get`](Self::get), with the triangle pairs it found (for debug views; empty when not
    /// recorded) and the pair's round side.
    pub fn insert(
        &mut self,
        key: (u64, u64),
        (pose_a, pose_b): (&Isometry, &Isometry),
        margin: f32,
        (manifold, round): (Option<&ContactManifold>, RoundSide),
        hits: &[[u32; 2]],
    ) {
        let to_local = |m: &ContactManifold| m.to_local(pose_a);
        let entry = Entry {
            b_in_a: pose_a.inv_mul(pose_b),
            round,
            margin,
            manifold: manifold.map(to_local),
            hits: hits.to_vec(),
            used: self.step,
        };
        self.entries.insert(key, entry);
    }

    /// The triangle pairs stored with pair `key` (empty without an entry).
    pub fn hits_of(&self, key: (u64, u64)) -> &[[u32; 2]] {
        self.entries.get(&key).map_or(&[], |e| &e.hits)
    }

    /// How many times an entry answered, since the cache was made.
    pub fn hits(&self) -> u64 {
        self.hits
    }

    /// The number of entries kept.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// True when no entry is kept.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::contacts::contact;
    use crate::geometry::{MeshCollider, TriMesh};

    #[test]
    fn box_pairs_answered_from_the_cache_match_a_fresh_test_within_0_1_mm_on_300_moves() {
        use crate::geometry::contacts::speculative_contact;
        let mut rng = crate::test_rng::TestRng::new(11);
        let a = Shape::cuboid(Vec3::new(0.5, 0.4, 0.3));
        let margin = 0.02;
        let mut cache = ManifoldCache::default();
        let mut worst = 0.0f32;
        for i in 0..300u64 {
            cache.begin_step();
            let b = Shape::cuboid(rng.vec3(0.1, 0.6));
            let Shape::Cuboid(cuboid) = &b else {
                unreachable!("made a cuboid")
            };
            // B on A's top face, turned about the normal, sunk up to 2 mm or up to 5 mm above.
            let lift = rng.range(-0.002, 0.005);
            let rest = Vec3::new(rng.range(-0.3, 0.3), rng.range(-0.3, 0.3), 0.3);
            let on_a = Isometry::new(
                rest + Vec3::Z * (cuboid.half_extents.z + lift),
                Quat::from_rotation_z(rng.range(-3.0, 3.0)),
            );
            let pose_a = Isometry::new(rng.vec3(-5.0, 5.0), rng.rotation());
            let pose_b = pose_a * on_a;
            let tested = speculative_contact(&a, &pose_a, &b, &pose_b, margin);
            let tested = (tested.as_ref(), RoundSide::Neither);
            cache.insert((i, 0), (&pose_a, &pose_b), margin, tested, &[]);
            // Then B moves, in A's frame, by at most 0.8 mm at its reach.
            let reach = b.bounding_radius();
            let angle = rng.range(0.0, 0.0004 / reach);
            let nudge = Isometry::new(
                rng.vec3(-1.0, 1.0).normalize() * 0.0004,
                Quat::from_axis_angle(rng.vec3(-1.0, 1.0).normalize(), angle),
            );
            let moved = pose_a * (on_a * nudge);
            let cached = cache.get((i, 0), (&pose_a, &moved), reach, margin);
            let fresh = speculative_contact(&a, &pose_a, &b, &moved, margin);
            let (Some(Some(cached)), Some(fresh)) = (cached, fresh) else {
                panic!("move {i}: a touching pair must be a hit and touch");
            };
            assert!(cached.normal.abs_diff_eq(fresh.normal, 1e-3), "move {i}");
            let error = (cached.max_depth() - fresh.max_depth()).abs();
            worst = worst.max(error);
            // The correction is exact for B's translation and first order in its turn: far
            // inside the cache's 1 mm (without it, the 0.4 mm moves along the normal show).
            assert!(error < 1e-4, "move {i}: depth off by {error} m");
        }
        eprintln!("box pairs from the cache: worst depth error {worst} m");
    }

    #[test]
    fn a_capsule_rolling_on_a_box_from_the_cache_keeps_the_fresh_normal_and_points_within_1e_5() {
        // A log on a box rolls and turns a little about the vertical, as either shape of the
        // pair; the fresh test is the oracle. Kept in A's frame (as before the round side was
        // followed) the normal tilted by the roll and the points stayed behind.
        use crate::geometry::contacts::speculative_contact;
        let log = Shape::capsule(0.4, 0.5);
        let floor = Shape::cuboid(Vec3::new(1.5, 1.5, 0.5));
        let floor_at = Isometry::from_translation(Vec3::new(0.2, -0.1, -0.5));
        let lying = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
        let margin = 0.005;
        for log_first in [true, false] {
            let (round, reach) = if log_first {
                (RoundSide::A, floor.bounding_radius())
            } else {
                (RoundSide::B, log.bounding_radius())
            };
            assert_eq!(
                round,
                if log_first {
                    RoundSide::of(&log, &floor)
                } else {
                    RoundSide::of(&floor, &log)
                }
            );
            let test = |log_at: &Isometry| {
                if log_first {
                    (
                        *log_at,
                        floor_at,
                        speculative_contact(&log, log_at, &floor, &floor_at, margin),
                    )
                } else {
                    (
                        floor_at,
                        *log_at,
                        speculative_contact(&floor, &floor_at, &log, log_at, margin),
                    )
                }
            };
            let start = Isometry::new(Vec3::new(0.3, 0.0, 0.5), lying);
            let mut cache = ManifoldCache::default();
            cache.begin_step();
            let (pa, pb, tested) = test(&start);
            cache.insert((1, 2), (&pa, &pb), margin, (tested.as_ref(), round), &[]);
            // Rolled along x by up to 0.1 mm (turning about y) and turned about z: within the
            // cache's 1 mm at the far side of the floor.
            for (roll, yaw) in [(0.0001, 0.0), (-0.00008, 0.0), (0.0001, 0.0001)] {
                let turn = Quat::from_rotation_z(yaw) * Quat::from_rotation_y(roll / 0.5);
                let at = Isometry::new(start.translation + Vec3::X * roll, turn * lying);
                let (pa, pb, fresh) = test(&at);
                let cached = cache.get((1, 2), (&pa, &pb), reach, margin);
                let (Some(Some(cached)), Some(fresh)) = (cached, fresh) else {
                    panic!("log first {log_first}, roll {roll}: a hit that touches");
                };
                let what = format!("log first {log_first}, roll {roll}, yaw {yaw}");
                assert!(
                    cached.normal.abs_diff_eq(fresh.normal, 1e-6),
                    "{what}: {cached:?}"
                );
                for (c, f) in cached.points().iter().zip(fresh.points()) {
                    assert!(
                        c.point.distance(f.point) < 1e-5,
                        "{what}: {cached:?} {fresh:?}"
                    );
                    assert!((c.depth - f.depth).abs() < 1e-5, "{what}");
                }
            }
        }
    }

    #[test]
    fn a_resting_mesh_is_answered_from_the_cache_within_1mm_and_retested_beyond() {
        let floor =
            Shape::TriMesh(MeshCollider::new(TriMesh::grid_floor(4.0, 8).unwrap()).unwrap());
        let body =
            Shape::TriMesh(MeshCollider::new(TriMesh::cuboid(Vec3::splat(0.5)).unwrap()).unwrap());
        let ground = Isometry::from_translation(Vec3::new(0.3, -0.2, 0.0));
        // Off the floor's grid lines, so no face of the box lies along a floor edge.
        let at = |dz: f32, turn: f32| {
            Isometry::new(
                Vec3::new(0.43, -0.27, 0.49 + dz),
                Quat::from_rotation_z(turn),
            )
        };
        let mut cache = ManifoldCache::default();
        cache.begin_step();
        let first = contact(&floor, &ground, &body, &at(0.0, 0.0));
        assert!(first.is_some());
        let tested = (&ground, &at(0.0, 0.0));
        cache.insert(
            (1, 2),
            tested,
            0.0,
            (first.as_ref(), RoundSide::Neither),
            &[[3, 4]],
        );
        // Sunk 0.4 mm and turned a little: reused, the depth following the sink exactly.
        cache.begin_step();
        let moved = at(-0.0004, 0.0005);
        let reused = cache
            .get((1, 2), (&ground, &moved), 0.87, 0.0)
            .unwrap()
            .unwrap();
        let truth = contact(&floor, &ground, &body, &moved).unwrap();
        assert!((reused.max_depth() - truth.max_depth()).abs() < 1e-4);
        assert!(reused.normal.abs_diff_eq(truth.normal, 1e-5));
        assert_eq!(cache.hits(), 1);
        assert_eq!(cache.hits_of((1, 2)), &[[3, 4]]);
        // 2 mm away, or after a step nobody asked: tested again.
        assert!(
            cache
                .get((1, 2), (&ground, &at(0.002, 0.0)), 0.87, 0.0)
                .is_none()
        );
        // Looking 2 mm farther ahead than the test did (a body thrown): tested again.
        assert!(cache.get((1, 2), (&ground, &moved), 0.87, 0.002).is_none());
        cache.begin_step();
        cache.begin_step();
        assert!(cache.get((1, 2), (&ground, &moved), 0.87, 0.0).is_none());
        assert!(cache.is_empty());
    }
}

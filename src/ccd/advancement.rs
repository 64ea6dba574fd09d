//! Conservative advancement (Mirtich 1996, *Impulse-based dynamic simulation of rigid body
//! systems*, PhD thesis, §3; Mirtich and Canny 1995): a time of impact for any pair with a
//! distance function and a bound on how fast that distance can shrink.
//!
//! If the distance at `t` is `δ` and it shrinks by at most `v` per unit of `t`, no contact can
//! happen before `t + δ/v`: advancing by that much is safe. Repeating converges to the first
//! contact from below, so the answer is **never later than the true one** — the property that
//! keeps a body from tunnelling. Convergence is immediate for a head-on approach and slow for a
//! grazing one (each step shrinks the gap by a factor `1 − cos θ`, θ the angle between the motion
//! and the separating direction), hence the iteration cap.
//!
//! Used as the generic fallback (any obstacle with a closest-point function) and as the
//! cross-check of the exact queries in the tests.

use super::{InitialOverlap, SphereSweep, Toi};
use glam::Vec3;

/// Iterations [`toi_sphere_by_advancement`] allows before giving up with a safe, early `t`.
pub const DEFAULT_MAX_ADVANCEMENT_ITERATIONS: u32 = 256;

/// The outcome of [`conservative_advancement`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Advancement {
    /// The distance fell within the tolerance at `t` (no contact before `t`).
    Contact {
        /// Time of the contact, in `[0, 1]`.
        t: f32,
        /// Distance evaluations used.
        iterations: u32,
    },
    /// No contact in `[0, 1]`.
    NoContact {
        /// Distance evaluations used.
        iterations: u32,
    },
    /// The iteration cap was reached (a grazing approach) or the distance was NaN: there is no
    /// contact before `t`, and nothing is known after it.
    Unresolved {
        /// The last safe time.
        t: f32,
    },
}

/// Advances `t` from 0 by `distance(t) / max_approach_speed` until `distance(t) <= tolerance`.
///
/// `distance(t)` is the separation at time `t` (negative when overlapping) and
/// `max_approach_speed` an upper bound on how fast it can decrease per unit of `t` (for a
/// translating body, the length of its displacement relative to the obstacle). A speed that is
/// not positive means the distance cannot shrink: the answer is then decided at `t = 0`.
/// A touch at exactly `t = 1` counts.
pub fn conservative_advancement(
    mut distance: impl FnMut(f32) -> f32,
    max_approach_speed: f32,
    tolerance: f32,
    max_iterations: u32,
) -> Advancement {
    let mut t = 0.0f32;
    for iteration in 1..=max_iterations {
        let gap = distance(t);
        if gap.is_nan() {
            return Advancement::Unresolved { t };
        }
        if gap <= tolerance {
            return Advancement::Contact {
                t,
                iterations: iteration,
            };
        }
        if max_approach_speed.is_nan() || max_approach_speed <= 0.0 {
            return Advancement::NoContact {
                iterations: iteration,
            };
        }
        let next = t + gap / max_approach_speed;
        if next > 1.0 {
            // Safe to skip to 1; a touch there still counts.
            return if distance(1.0) <= tolerance {
                Advancement::Contact {
                    t: 1.0,
                    iterations: iteration + 1,
                }
            } else {
                Advancement::NoContact {
                    iterations: iteration + 1,
                }
            };
        }
        if next == t {
            // The step fell below the resolution of t: further steps cannot progress.
            return Advancement::Unresolved { t };
        }
        t = next;
    }
    Advancement::Unresolved { t }
}

/// Time of impact of the sweep against any obstacle given by its `closest_point` function (the
/// point of the obstacle nearest to a query point; a point inside a solid obstacle is its own
/// closest point), by [`conservative_advancement`] with the sweep's tolerance and the speed bound
/// `|displacement|`.
///
/// The normal points from the closest point to the centre (`-d/|d|` when they coincide, world up
/// without motion); the point is the closest point. A [`Advancement::Unresolved`] run is
/// reported as an impact at its last safe `t`, which is early, never late. With
/// [`InitialOverlap::ApproachingOnly`] a contact at the start is skipped (giving `None`) when the
/// displacement does not go deeper; that is right for convex obstacles only.
pub fn toi_sphere_by_advancement(
    sweep: &SphereSweep,
    mut closest_point: impl FnMut(Vec3) -> Vec3,
    max_iterations: u32,
) -> Option<Toi> {
    let r = sweep.radius();
    let speed = sweep.displacement().length();
    let outcome = conservative_advancement(
        |t| {
            let c = sweep.position_at(t);
            c.distance(closest_point(c)) - r
        },
        speed,
        sweep.tolerance(),
        max_iterations,
    );
    let t = match outcome {
        Advancement::Contact { t, .. } | Advancement::Unresolved { t } => t,
        Advancement::NoContact { .. } => return None,
    };
    let c = sweep.position_at(t);
    let point = closest_point(c);
    let normal = super::swept_point::unit_or(c - point, || sweep.fallback_normal());
    let toi = Toi { t, normal, point };
    let skip = t == 0.0
        && sweep.initial_overlap() == InitialOverlap::ApproachingOnly
        && sweep.displacement().dot(normal) >= 0.0;
    (!skip).then_some(toi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn head_on_converges_in_one_step_and_grazing_hits_the_cap() {
        // Distance shrinking exactly at the bound: 2 − 4t, contact at 0.5 after one advance.
        let a = conservative_advancement(|t| 2.0 - 4.0 * t, 4.0, 1e-6, 10);
        assert_eq!(
            a,
            Advancement::Contact {
                t: 0.5,
                iterations: 2
            }
        );
        // Shrinking at a hundredth of the bound: many small steps.
        let slow = conservative_advancement(|t| 0.5 - 0.5 * t, 50.0, 1e-6, 10);
        assert!(matches!(slow, Advancement::Unresolved { t } if t > 0.0 && t < 1.0));
        let enough = conservative_advancement(|t| 0.5 - 0.5 * t, 50.0, 1e-5, 2000);
        assert!(matches!(enough, Advancement::Contact { t, .. } if t > 0.9999 && t <= 1.0));
    }

    #[test]
    fn misses_touch_at_one_and_degenerate_inputs() {
        assert!(matches!(
            conservative_advancement(|t| 3.0 - t, 1.0, 1e-6, 100),
            Advancement::NoContact { .. }
        ));
        assert!(matches!(
            conservative_advancement(|t| 1.0 - t, 1.0, 0.0, 100),
            Advancement::Contact { t: 1.0, .. }
        ));
        assert!(matches!(
            conservative_advancement(|_| 1.0, 0.0, 1e-6, 100),
            Advancement::NoContact { iterations: 1 }
        ));
        assert!(matches!(
            conservative_advancement(|_| 0.0, f32::NAN, 1e-6, 100),
            Advancement::Contact { t: 0.0, .. }
        ));
        assert!(matches!(
            conservative_advancement(|_| f32::NAN, 1.0, 1e-6, 100),
            Advancement::Unresolved { t: 0.0 }
        ));
        assert!(matches!(
            conservative_advancement(|_| 1.0, 1.0, 1e-6, 0),
            Advancement::Unresolved { t: 0.0 }
        ));
    }

    #[test]
    fn sphere_against_a_closest_point_function() {
        // A ball of radius 1 at the origin as a closest-point function.
        let ball = |p: Vec3| p.clamp_length_max(1.0);
        let sweep = SphereSweep::new(Vec3::new(-5.0, 0.0, 0.0), 0.5, Vec3::X * 10.0).unwrap();
        let toi = toi_sphere_by_advancement(&sweep, ball, 64).unwrap();
        assert!((toi.t - 0.35).abs() < 1e-5 && (toi.normal + Vec3::X).length() < 1e-5);
        let away = SphereSweep::new(Vec3::new(-5.0, 0.0, 0.0), 0.5, -Vec3::X).unwrap();
        assert!(toi_sphere_by_advancement(&away, ball, 64).is_none());
        let inside = SphereSweep::new(Vec3::ZERO, 0.5, Vec3::X).unwrap();
        let toi = toi_sphere_by_advancement(&inside, ball, 64).unwrap();
        assert_eq!((toi.t, toi.normal), (0.0, -Vec3::X));
    }
}

//! The moving sphere of a continuous-collision query: where it starts, how big it is, how far it
//! travels during the step, and what to do when it already touches something at the start.
//!
//! Validated once at construction, so that every query can trust its numbers.

use super::Toi;
use crate::bounding::{Aabb, FIT_PAD_RELATIVE};
use crate::geometry::Isometry;
use glam::Vec3;
use std::fmt;

/// Relative size of the contact tolerance: see [`SphereSweep::tolerance`].
pub const CONTACT_TOLERANCE_RELATIVE: f32 = 1e-5;

/// What a query reports when the sphere is already in contact at `t = 0`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum InitialOverlap {
    /// Report every contact at the start as an impact at `t = 0`.
    #[default]
    Report,
    /// Report a contact at the start only if the displacement goes deeper
    /// (`displacement · normal < 0`); a contact being left or slid along is ignored and the
    /// query looks further. This is what a step loop wants after it moved a body to its impact
    /// point and turned its velocity: the surface it rests on must not stop it again.
    ApproachingOnly,
}

/// Why a sweep cannot be built.
#[derive(Clone, Debug, PartialEq)]
pub enum SweepError {
    /// A centre with a NaN or infinite coordinate.
    NonFiniteCenter(Vec3),
    /// A radius that is negative, NaN or infinite.
    BadRadius(f32),
    /// A displacement with a NaN or infinite coordinate, or whose end point overflows.
    NonFiniteDisplacement(Vec3),
}

impl fmt::Display for SweepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFiniteCenter(c) => write!(f, "sweep centre must be finite, got {c}"),
            Self::BadRadius(r) => write!(f, "sweep radius must be finite and >= 0, got {r}"),
            Self::NonFiniteDisplacement(d) => {
                write!(
                    f,
                    "sweep displacement must be finite (end point too), got {d}"
                )
            }
        }
    }
}

impl std::error::Error for SweepError {}

/// A sphere of `radius` whose centre moves from `center` to `center + displacement` during the
/// step. Fields are private: a `SphereSweep` is always valid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereSweep {
    center: Vec3,
    radius: f32,
    displacement: Vec3,
    initial_overlap: InitialOverlap,
}

impl SphereSweep {
    /// A sweep with the [`InitialOverlap::Report`] policy; refuses non-finite numbers, a
    /// negative radius and an end point that overflows `f32`.
    pub fn new(center: Vec3, radius: f32, displacement: Vec3) -> Result<Self, SweepError> {
        if !center.is_finite() {
            return Err(SweepError::NonFiniteCenter(center));
        }
        if !(radius.is_finite() && radius >= 0.0) {
            return Err(SweepError::BadRadius(radius));
        }
        if !(displacement.is_finite() && (center + displacement).is_finite()) {
            return Err(SweepError::NonFiniteDisplacement(displacement));
        }
        Ok(Self {
            center,
            radius,
            displacement,
            initial_overlap: InitialOverlap::Report,
        })
    }

    /// The same sweep with another policy for contacts at the start.
    #[must_use]
    pub fn with_initial_overlap(mut self, policy: InitialOverlap) -> Self {
        self.initial_overlap = policy;
        self
    }

    /// Centre at `t = 0`.
    pub fn center(&self) -> Vec3 {
        self.center
    }

    /// Radius (`>= 0`; zero makes the query a ray test).
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// Motion of the centre over the whole step.
    pub fn displacement(&self) -> Vec3 {
        self.displacement
    }

    /// The policy for contacts at the start.
    pub fn initial_overlap(&self) -> InitialOverlap {
        self.initial_overlap
    }

    /// Centre at fraction `t` of the step.
    #[inline]
    pub fn position_at(&self, t: f32) -> Vec3 {
        self.center + self.displacement * t
    }

    /// The distance under which the sphere counts as in contact for iterative methods, and the
    /// slack of the exact ones: `1e-5 × (r + |d|)`, relative to the sizes of the query so it
    /// means the same at every scale.
    pub fn tolerance(&self) -> f32 {
        CONTACT_TOLERANCE_RELATIVE * (self.radius + self.displacement.length())
    }

    /// The box holding the sphere over the whole step (for broad-phase queries).
    pub fn swept_aabb(&self) -> Aabb {
        let start = Aabb::from_center_half_extents(self.center, Vec3::splat(self.radius));
        super::swept_aabb(&start, self.displacement)
    }

    /// The same sweep seen from the frame of `pose` (for obstacles stored in their own frame).
    pub(crate) fn in_frame(&self, pose: &Isometry) -> Self {
        Self {
            center: pose.inverse_transform_point(self.center),
            displacement: pose.inverse_transform_vector(self.displacement),
            ..*self
        }
    }

    /// The same sweep moving by `displacement` instead (relative motion of two spheres).
    pub(crate) fn with_displacement(&self, displacement: Vec3) -> Self {
        Self {
            displacement,
            ..*self
        }
    }

    /// The slack of face-inside tests: the tolerance plus the rounding of coordinates of the
    /// query's magnitude (so a ray through an edge shared by two faces hits one of them).
    pub(crate) fn slack(&self) -> f32 {
        let magnitude = self
            .center
            .abs()
            .max((self.center + self.displacement).abs())
            .max_element();
        self.tolerance() + FIT_PAD_RELATIVE * magnitude
    }

    /// The impact at `t = 0` of a contact found by a static test (normal from the obstacle to
    /// the sphere), or `None` when the policy says to ignore it.
    pub(crate) fn initial_contact(&self, normal: Vec3, point: Vec3) -> Option<Toi> {
        // Renormalised: the static tests divide by a length that can be subnormal.
        let normal = if normal.is_normalized() {
            normal
        } else {
            super::swept_point::unit_or(normal, || self.fallback_normal())
        };
        let keep = match self.initial_overlap {
            InitialOverlap::Report => true,
            InitialOverlap::ApproachingOnly => self.displacement.dot(normal) < 0.0,
        };
        keep.then_some(Toi {
            t: 0.0,
            normal,
            point,
        })
    }

    /// The impact at `t` with the given normal (from the obstacle to the sphere): the contact
    /// point is on the sphere's surface, where it meets the obstacle.
    pub(crate) fn impact(&self, t: f32, normal: Vec3) -> Toi {
        Toi {
            t,
            normal,
            point: self.position_at(t) - normal * self.radius,
        }
    }

    /// The normal used where the surface defines none (a ray hitting an edge or a vertex):
    /// straight back along the motion, or [`FALLBACK_NORMAL`] without motion.
    ///
    /// [`FALLBACK_NORMAL`]: crate::geometry::contacts::FALLBACK_NORMAL
    pub(crate) fn fallback_normal(&self) -> Vec3 {
        fallback_normal_for(self.displacement)
    }
}

/// See [`SphereSweep::fallback_normal`].
pub(crate) fn fallback_normal_for(displacement: Vec3) -> Vec3 {
    super::swept_point::unit_or(-displacement, || crate::geometry::contacts::FALLBACK_NORMAL)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_numbers_are_refused_with_the_culprit() {
        let ok = SphereSweep::new(Vec3::ONE, 0.5, Vec3::X);
        assert!(ok.is_ok());
        assert!(matches!(
            SphereSweep::new(Vec3::new(f32::NAN, 0.0, 0.0), 1.0, Vec3::X),
            Err(SweepError::NonFiniteCenter(_))
        ));
        assert!(matches!(
            SphereSweep::new(Vec3::ZERO, -1.0, Vec3::X),
            Err(SweepError::BadRadius(_))
        ));
        assert!(matches!(
            SphereSweep::new(Vec3::ZERO, f32::INFINITY, Vec3::X),
            Err(SweepError::BadRadius(_))
        ));
        assert!(matches!(
            SphereSweep::new(Vec3::ZERO, 1.0, Vec3::new(0.0, f32::NEG_INFINITY, 0.0)),
            Err(SweepError::NonFiniteDisplacement(_))
        ));
        assert!(matches!(
            SphereSweep::new(Vec3::X * 3e38, 1.0, Vec3::X * 3e38),
            Err(SweepError::NonFiniteDisplacement(_))
        ));
        assert!(!SweepError::BadRadius(-1.0).to_string().is_empty());
    }

    #[test]
    fn swept_aabb_holds_the_sphere_at_both_ends() {
        let s = SphereSweep::new(Vec3::new(1.0, 2.0, 3.0), 0.5, Vec3::new(-4.0, 0.0, 2.0)).unwrap();
        let b = s.swept_aabb();
        assert_eq!(b.min, Vec3::new(-3.5, 1.5, 2.5));
        assert_eq!(b.max, Vec3::new(1.5, 2.5, 5.5));
    }
}

//! Vectors applied at world points (forces, impulses), summed with their moment, for
//! [`ForceAtPoint`](super::ForceAtPoint) and [`Impulse`](super::Impulse).
//!
//! The moment is kept about the first point added, not the world origin: a body 10⁵ m out
//! would otherwise get `Σ p × v − c × Σ v`, two numbers of size `10⁵ |v|` whose difference, the
//! lever's `0.5 |v|`, keeps only a few bits (about 1 % of it). About a point near the body both
//! terms stay the size of the lever.

use glam::Vec3;

/// A sum of vectors at points and their moment about `reference`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct PointSum {
    total: Vec3,
    /// The first point added: what `moment` is taken about.
    reference: Option<Vec3>,
    /// `Σ (p − reference) × v`.
    moment: Vec3,
}

impl PointSum {
    /// Adds `v` acting at `point`.
    pub fn add(&mut self, v: Vec3, point: Vec3) {
        let reference = *self.reference.get_or_insert(point);
        self.total += v;
        self.moment += (point - reference).cross(v);
    }

    /// The sum of the vectors.
    pub fn total(&self) -> Vec3 {
        self.total
    }

    /// Their moment about the world point `center`.
    pub fn moment_about(&self, center: Vec3) -> Vec3 {
        self.reference
            .map_or(Vec3::ZERO, |r| self.moment + (r - center).cross(self.total))
    }

    /// True when every number held is finite.
    pub fn is_finite(&self) -> bool {
        self.total.is_finite()
            && self.moment.is_finite()
            && self.reference.is_none_or(|r| r.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn the_moment_far_from_the_origin_is_exact_within_1e_6_relative() {
        let center = Vec3::new(123_456.7, -98_765.4, 3.3);
        let mut sum = PointSum::default();
        let mut exact = DVec3::ZERO;
        for (offset, v) in [
            (Vec3::new(0.5, 0.1, -0.2), Vec3::new(1.0, 2.0, -0.5)),
            (Vec3::new(-0.3, 0.4, 0.25), Vec3::new(-0.7, 0.3, 1.1)),
        ] {
            let point = center + offset;
            sum.add(v, point);
            exact += (point.as_dvec3() - center.as_dvec3()).cross(v.as_dvec3());
        }
        let got = sum.moment_about(center).as_dvec3();
        assert!(
            (got - exact).length() <= 1e-6 * exact.length(),
            "{got} vs {exact}"
        );
        assert_eq!(PointSum::default().moment_about(center), Vec3::ZERO);
    }
}

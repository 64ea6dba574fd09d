//! A small seeded generator for the unit tests' random scenes (a linear congruential one,
//! Knuth's MMIX constants: the tests need spread and repeatability, not quality, and no
//! dependency).

use glam::{Quat, Vec3};

/// A seeded stream of floats (see the module doc).
pub(crate) struct TestRng(u64);

impl TestRng {
    /// The stream of `seed`.
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// In `[0, 1)`, from the state's top 24 bits.
    pub(crate) fn unit(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    /// In `[lo, hi)`.
    pub(crate) fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }

    /// Each component in `[lo, hi)`.
    pub(crate) fn vec3(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }

    /// In `0..n`.
    pub(crate) fn below(&mut self, n: u32) -> u32 {
        ((self.unit() * n as f32) as u32).min(n.saturating_sub(1))
    }

    /// A turn about an axis tilted up from the x–y plane, by any angle.
    pub(crate) fn rotation(&mut self) -> Quat {
        let axis = Vec3::new(self.range(-1.0, 1.0), self.range(-1.0, 1.0), 0.5).normalize();
        Quat::from_axis_angle(axis, self.range(0.0, std::f32::consts::TAU))
    }
}

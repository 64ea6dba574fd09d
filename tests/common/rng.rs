//! A small seeded generator (SplitMix64, Steele, Lea and Flood 2014): reproducible streams
//! without a dependency.

use glam::{Quat, Vec3};
use urto::geometry::Isometry;

pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }

    /// Each component uniform in `[lo, hi)`.
    pub fn vec3(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }

    /// `10^x` for `x` uniform in `[lo, hi)`: sizes and masses spread over decades.
    pub fn decades(&mut self, lo: f32, hi: f32) -> f32 {
        10f32.powf(self.range(lo, hi))
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f32) -> bool {
        self.unit() < p
    }

    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }

    /// Uniform in the ball of radius `r`.
    pub fn in_ball(&mut self, r: f32) -> Vec3 {
        loop {
            let v = Vec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            if v.length_squared() <= 1.0 {
                return v * r;
            }
        }
    }

    /// Uniform unit direction.
    pub fn direction(&mut self) -> Vec3 {
        loop {
            let v = self.in_ball(1.0);
            if let Some(d) = v.try_normalize() {
                return d;
            }
        }
    }

    /// Uniform random rotation (Shoemake 1992).
    pub fn rotation(&mut self) -> Quat {
        let (u1, u2, u3) = (self.unit(), self.unit(), self.unit());
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        let tau = std::f32::consts::TAU;
        Quat::from_xyzw(
            a * (tau * u2).sin(),
            a * (tau * u2).cos(),
            b * (tau * u3).sin(),
            b * (tau * u3).cos(),
        )
        .normalize()
    }

    /// A rigid placement of B near A: B's origin at a random distance up to `reach` in a random
    /// direction; one placement in eight is a pure translation (exercising the rotation-free
    /// paths of the BV tests).
    pub fn placement(&mut self, reach: f32) -> Isometry {
        let translation = self.direction() * self.range(0.0, reach);
        let rotation = if self.below(8) == 0 {
            Quat::IDENTITY
        } else {
            self.rotation()
        };
        Isometry::new(translation, rotation)
    }
}

//! What a game gives a body besides forces: an instant kick ([`Impulse`], a jump, an explosion,
//! a bullet's hit) and its own share of gravity ([`GravityScale`], a balloon, a feather, a
//! floating power-up), as Avian's `ExternalImpulse` / `GravityScale` and rapier's
//! `apply_impulse` / `gravity_scale` give.

use super::point_sum::PointSum;
use bevy_ecs::prelude::*;
use glam::Vec3;

/// Impulses (N·s) applied at the start of the next physics step, then cleared: the velocity
/// jumps by `J / m` (and the spin by `I⁻¹ L`) at once, whatever the step length, where a
/// [`Force`](super::Force) acts over the step. A body without it pays nothing.
///
/// ```
/// # use urto::prelude::*;
/// # use glam::Vec3;
/// let mut kick = Impulse::default();
/// kick.add(Vec3::Z * 5.0); // a jump: 5 N·s up, through the centre of mass
/// kick.add_at_point(Vec3::X * 2.0, Vec3::new(0.0, 0.0, 1.0)); // and a shove 1 m up
/// assert_eq!(kick.linear(), Vec3::new(2.0, 0.0, 5.0));
/// assert_eq!(kick.angular_about(Vec3::ZERO), Vec3::new(0.0, 2.0, 0.0));
/// ```
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
#[component(summary_tick)]
pub struct Impulse {
    /// Impulses through the centre of mass.
    through_center: Vec3,
    /// Impulses at points and their moment (exact far from the origin).
    at_points: PointSum,
    /// Angular impulses (N·m·s, world axes).
    angular: Vec3,
}

impl Impulse {
    /// A linear impulse through the centre of mass.
    pub fn new(linear: Vec3) -> Self {
        Self {
            through_center: linear,
            ..Self::default()
        }
    }

    /// Adds a linear impulse through the centre of mass (it does not turn the body).
    pub fn add(&mut self, impulse: Vec3) {
        self.through_center += impulse;
    }

    /// Adds a linear impulse at the world `point`: it also turns the body about its centre of
    /// mass (where that is at the step's start).
    pub fn add_at_point(&mut self, impulse: Vec3, point: Vec3) {
        self.at_points.add(impulse, point);
    }

    /// Adds an angular impulse (N·m·s about world axes).
    pub fn add_angular(&mut self, impulse: Vec3) {
        self.angular += impulse;
    }

    /// The sum of the linear impulses.
    pub fn linear(&self) -> Vec3 {
        self.through_center + self.at_points.total()
    }

    /// The angular impulse about the world point `center`: the angular impulses plus the
    /// moments of the impulses at points.
    pub fn angular_about(&self, center: Vec3) -> Vec3 {
        self.angular + self.at_points.moment_about(center)
    }

    /// True when nothing was added.
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }

    /// True when every sum is finite.
    pub fn is_finite(&self) -> bool {
        self.through_center.is_finite() && self.angular.is_finite() && self.at_points.is_finite()
    }
}

/// How much of the world's [`Gravity`](crate::settings::Gravity) pulls this body: 1 is all of
/// it (the default without the component), 0 none (it floats), negative pulls it up. Applied as
/// the force `(s − 1) m g` on top of gravity, so it works with every integrator and solver. Not
/// finite quarantines the body.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[component(summary_tick)]
pub struct GravityScale(pub f32);

impl Default for GravityScale {
    fn default() -> Self {
        Self(1.0)
    }
}

//! How far ahead the broad and narrow phases look for contacts when the solver detects once per
//! step: each moving body's speculative margin.
//!
//! The solver sees only the contacts found at the step's start, so a contact must be found
//! while the bodies are still as far apart as they can close in one step (Catto, "Speculative
//! Contacts", 2013). A body's margin is a fixed distance (Box2D's speculative distance, 4 × its
//! 5 mm slop) plus the bound on its motion over the step ([`motion_bound`]: speed, gravity's
//! pull and the turning of its surface), capped at the body's own reach: a margin much longer
//! than the body makes ghost contacts (two fast bodies whose paths pass close are stopped as if
//! they met, Catto's caveat), and a body that moves farther than its size in a step is the
//! business of continuous collision, which sweeps it against the scenery after the solve
//! ([`CcdSettings`](crate::plugins::CcdSettings): by default exactly the bodies faster than
//! that). The broad phase grows each moving body's volume by its margin; the narrow phase tests
//! a pair with the sum of its two bodies' margins.

use crate::components::{AngularVelocity, BoundingVolume, Velocity};
use crate::geometry::contacts::motion_bound;
use crate::settings::{Gravity, PhysicsTimestep};
use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemParam;

/// The speculative margin's two numbers; inserted by
/// [`SoftStepPlugin`](super::SoftStepPlugin) (without it, contacts are found touching only).
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct SpeculativeMargin {
    /// Looked ahead always (m): contacts of resting bodies stay found while the solver holds
    /// them a hair apart.
    pub distance: f32,
    /// Most motion in one step covered, in multiples of the body's reach (half its volume's
    /// diagonal).
    pub reach_ratio: f32,
}

impl Default for SpeculativeMargin {
    fn default() -> Self {
        Self {
            distance: 0.02,
            reach_ratio: 1.0,
        }
    }
}

/// The resources a [`Lookahead`] is made of, as one system parameter.
#[derive(SystemParam)]
pub(crate) struct LookaheadParams<'w> {
    margin: Option<Res<'w, SpeculativeMargin>>,
    timestep: Option<Res<'w, PhysicsTimestep>>,
    gravity: Option<Res<'w, Gravity>>,
}

impl LookaheadParams<'_> {
    /// This step's lookahead.
    pub fn get(&self) -> Lookahead {
        Lookahead::new(
            self.margin.as_deref(),
            self.timestep.as_deref(),
            self.gravity.as_deref(),
        )
    }
}

/// A system's view of the margin for this step: the settings, the step and gravity.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Lookahead {
    margin: Option<SpeculativeMargin>,
    dt: f32,
    gravity: f32,
}

impl Lookahead {
    /// The margin of this step, or none when no [`SpeculativeMargin`] is in the world.
    pub fn new(
        margin: Option<&SpeculativeMargin>,
        timestep: Option<&PhysicsTimestep>,
        gravity: Option<&Gravity>,
    ) -> Self {
        Self {
            margin: margin.copied(),
            dt: timestep.map_or(0.0, |t| t.substep_dt()),
            gravity: gravity.map_or(0.0, |g| g.acceleration().length()),
        }
    }

    /// The margin of a body with these velocities and this volume; 0 for a body that does not
    /// move (no velocity) or without a margin.
    pub fn of(
        &self,
        v: Option<&Velocity>,
        w: Option<&AngularVelocity>,
        volume: &BoundingVolume,
    ) -> f32 {
        let (Some(m), Some(v)) = (self.margin, v) else {
            return 0.0;
        };
        let (spin, reach) = (w.map_or(0.0, |w| w.0.length()), volume.reach());
        let motion = motion_bound(v.0.length(), spin, reach, self.gravity, self.dt);
        let d = m.distance + motion.min(m.reach_ratio * reach);
        if d.is_finite() { d.max(0.0) } else { 0.0 }
    }
}

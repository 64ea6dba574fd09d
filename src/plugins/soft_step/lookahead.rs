//! How far ahead the broad and narrow phases look for contacts when the solver detects once per
//! step: each moving body's speculative margin, and each pair's.
//!
//! The solver sees only the contacts found at the step's start, so a contact must be found
//! while the bodies are still as far apart as they can close in one step (Catto, "Speculative
//! Contacts", 2013). A body's margin is a fixed distance plus the bound on its motion over the
//! step ([`motion_bound`]: speed, gravity's pull and the turning of its surface), capped at the
//! body's own reach: a margin much longer than the body makes ghost contacts (two fast bodies
//! whose paths pass close are stopped as if they met, Catto's caveat), and a body that moves
//! farther than its size in a step is the business of continuous collision, which sweeps it
//! against the scenery after the solve ([`CcdSettings`](crate::plugins::CcdSettings): by default
//! exactly the bodies faster than that). The broad phase grows each moving body's volume by its
//! margin.
//!
//! The narrow phase tests a pair with a tighter margin ([`Lookahead::pair`]): the fixed
//! distances of its moving bodies plus how far the two can close, which is their *relative*
//! motion (Avian's speculative margin follows the relative velocity too): each body's velocity
//! as the solver moves it (along its free axes), and gravity's pull on the bodies it pulls
//! (awake dynamic ones, along their free axes; not kinematic, sleeping or translation-locked
//! ones). Two boxes resting side by side, or one on the other, fall together under gravity and
//! close by nothing, where the sum of their own bounds read 3.4 mm at 60 Hz and four substeps;
//! the pair's closing is still capped by the sum of the two bodies' margins, so the broad
//! phase's grown volumes (re-indexed when a velocity or a [`GravityScale`] changes) always find
//! it. Gravity moves a body by `g dt² (n + 1) / 2n` over the solver's `n` symplectic Euler
//! substeps (`g dt²` for one, `0.625 g dt²` for the default four), which the bound takes
//! instead of the exact fall's `g dt² / 2`.
//!
//! What the bound leaves to the fixed distance: forces other than gravity (a body pushed hard
//! is caught by the contacts of the next step, or by CCD); a sleeper that a contact wakes
//! within the solve, counted unpulled (at most the fall above, 1.7 mm at 60 Hz). A resting
//! body's growth in the broad phase is refreshed when its velocity or gravity scale changes,
//! and every body's when the margin settings, the step, gravity or the substep count do.
//!
//! The fixed distance is 2.5 mm per moving body (for metre-sized bodies: it is read times the
//! [`LengthUnit`]): 5 mm between two moving bodies, 2.5 mm between a moving one and a static one
//! (Avian's 5 mm contact tolerance; rapier predicts 2 mm; Box2D and Jolt look 2 cm ahead). It only
//! has to keep resting contacts found while the solver holds them a hair apart: the motion bound
//! covers the rest. At 2 cm per body the 1 cm gaps between the boxes of a row became 190 contacts
//! more in a 210-box pyramid (590 against 400), a quarter of its awake step.

use crate::components::{AngularVelocity, BoundingVolume, GravityScale, Velocity};
use crate::geometry::contacts::{motion_bound, raw_motion_bound};
use crate::geometry::length_or_zero;
use crate::settings::{Gravity, LengthUnit, PhysicsTimestep};
use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemParam;
use glam::Vec3;

/// The speculative margin's two numbers; inserted by
/// [`SoftStepPlugin`](super::SoftStepPlugin) (without it, contacts are found touching only).
/// Checked when a game changes it: a NaN, infinite or negative value is refused with a warning
/// and the defaults back.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct SpeculativeMargin {
    /// Looked ahead always by each moving body (m; a pair of them looks twice as far): contacts
    /// of resting bodies stay found while the solver holds them a hair apart.
    pub distance: f32,
    /// Most motion in one step covered, in multiples of the body's reach (half its volume's
    /// diagonal).
    pub reach_ratio: f32,
}

impl Default for SpeculativeMargin {
    fn default() -> Self {
        Self {
            distance: 0.0025,
            reach_ratio: 1.0,
        }
    }
}

/// The resources a [`Lookahead`] is made of, as one system parameter.
#[derive(SystemParam)]
pub(crate) struct LookaheadParams<'w> {
    margin: Option<Res<'w, SpeculativeMargin>>,
    length: Option<Res<'w, LengthUnit>>,
    timestep: Option<Res<'w, PhysicsTimestep>>,
    gravity: Option<Res<'w, Gravity>>,
    solver: Option<Res<'w, super::SoftStepSolver>>,
}

impl LookaheadParams<'_> {
    /// This step's lookahead.
    pub fn get(&self) -> Lookahead {
        let substeps = self
            .solver
            .as_ref()
            // The count the solver will step with: unusable settings step with the defaults.
            .map_or(1, |s| s.solver.settings.usable().substeps);
        let unit = self.length.as_deref().map_or(1.0, |u| u.get());
        let margin = self.margin.as_deref().map(|m| SpeculativeMargin {
            distance: m.distance * unit,
            ..*m
        });
        Lookahead::new(
            margin.as_ref(),
            self.timestep.as_deref(),
            self.gravity.as_deref(),
        )
        .with_substeps(substeps)
    }
}

/// A system's view of the margin for this step: the settings, the step and gravity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Lookahead {
    margin: Option<SpeculativeMargin>,
    dt: f32,
    gravity: Vec3,
    /// How much farther than `g dt² / 2` the solver's substeps let a body fall: `(n + 1) / n`.
    euler: f32,
}

/// How the solver moves a body, for its part in its pairs' margins.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Moves {
    /// A dynamic body, by its velocity and gravity along its free translation axes (none
    /// pulled while it sleeps: the solver holds a sleeper still unless a contact wakes it).
    Dynamic { free: Vec3, asleep: bool },
    /// A kinematic body, by its velocity alone.
    Kinematic,
    /// Not at all (a body the solver does not take, such as one without a mass).
    Not,
}

impl Moves {
    /// The axes its velocity moves it along, and those gravity pulls it along (1 or 0 each).
    fn masks(self) -> (Vec3, Vec3) {
        match self {
            Moves::Dynamic { free, asleep } => (free, if asleep { Vec3::ZERO } else { free }),
            Moves::Kinematic => (Vec3::ONE, Vec3::ZERO),
            Moves::Not => (Vec3::ZERO, Vec3::ZERO),
        }
    }
}

/// A moving body's part in the margins of its pairs ([`Lookahead::pair`]); all zero for a
/// static body.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct BodyMotion {
    /// Its velocity as the solver moves it (m/s; along its free axes).
    velocity: Vec3,
    /// Gravity's pull on it (m/s²; none on a kinematic or sleeping body, none along its locked
    /// axes).
    pull: Vec3,
    /// How fast its surface can move by turning: spin × reach (m/s).
    turning: f32,
    /// Its fixed distance (m).
    distance: f32,
    /// Its own margin: the fixed distance and its motion bound over the step, capped at its
    /// reach (m); the broad phase grew its volume by this.
    own: f32,
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
            gravity: gravity.map_or(Vec3::ZERO, |g| g.acceleration()),
            euler: 2.0,
        }
    }

    /// The lookahead of a solver integrating in `substeps` symplectic Euler substeps (one
    /// without this call, the farthest fall; 0 counts as one).
    pub fn with_substeps(self, substeps: u32) -> Self {
        let n = substeps.max(1) as f32;
        Self {
            euler: (n + 1.0) / n,
            ..self
        }
    }

    /// The margin of a body with these velocities, volume and share of gravity (the broad
    /// phase grows its volume by it); 0 for a body that does not move (no velocity) or without
    /// a margin.
    pub fn of(
        &self,
        v: Option<&Velocity>,
        w: Option<&AngularVelocity>,
        volume: &BoundingVolume,
        scale: Option<&GravityScale>,
    ) -> f32 {
        // Its own bound does not depend on how the solver moves it.
        self.motion(v, w, volume, scale, Moves::Not).own
    }

    /// What a body brings to its pairs' margins, moved by the solver as `moves` says. Its own
    /// bound counts its whole velocity and gravity's pull whatever `moves` says, so that it is
    /// the same as the broad phase's. Always inlined: returned through memory, its result
    /// was read back in wider loads than it was written in, and the narrow phase waited on
    /// those stores for every body.
    #[inline(always)]
    pub fn motion(
        &self,
        v: Option<&Velocity>,
        w: Option<&AngularVelocity>,
        volume: &BoundingVolume,
        scale: Option<&GravityScale>,
        moves: Moves,
    ) -> BodyMotion {
        let (Some(m), Some(v)) = (self.margin, v) else {
            return BodyMotion::default();
        };
        let scale = scale.map_or(1.0, |s| s.0);
        let (spin, reach) = (w.map_or(0.0, |w| w.0.length()), volume.reach());
        let fall = scale.abs() * self.gravity.length();
        // The substeps' symplectic Euler falls `(n + 1) / n` times the `a/2` of `motion_bound`.
        let own = motion_bound(v.0.length(), spin, reach, fall * self.euler, self.dt)
            .min(m.reach_ratio * reach);
        let (moved, pulled) = moves.masks();
        let finite = length_or_zero;
        BodyMotion {
            velocity: v.0 * moved,
            pull: self.gravity * scale * pulled,
            turning: finite(spin * reach),
            distance: finite(m.distance),
            own: finite(finite(m.distance) + finite(own)),
        }
    }

    /// How far B moves relative to A over the step as the solver would move them alone (their
    /// velocities and gravity's pull, straight): where a speculative contact of two balls looks
    /// for their meeting (`sphere_sphere_on_approach`).
    pub fn relative_motion(&self, a: &BodyMotion, b: &BodyMotion) -> Vec3 {
        let fall = 0.5 * self.euler * self.dt * self.dt;
        (b.velocity - a.velocity) * self.dt + (b.pull - a.pull) * fall
    }

    /// The margin a pair is tested with: both fixed distances, plus how far the two can close
    /// in a step by their relative velocity and pull and their turning; at most the sum of
    /// their own margins (which the broad phase grew their volumes by), to the bit.
    pub fn pair(&self, a: &BodyMotion, b: &BodyMotion) -> f32 {
        // Symmetric to the bit (a sum of two, then of two): the broad phase's pair order follows
        // archetype order, which must not reach the result.
        let speed = (a.velocity - b.velocity).length() + (a.turning + b.turning);
        let pull = (a.pull - b.pull).length();
        let closing = raw_motion_bound(speed, pull * self.euler, self.dt);
        // Overflowed (or NaN): as far as the broad phase grew them.
        let closing = if closing.is_finite() {
            closing.max(0.0)
        } else {
            f32::INFINITY
        };
        length_or_zero((a.distance + b.distance + closing).min(a.own + b.own))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounding::Aabb;
    use crate::test_rng::TestRng;

    fn lookahead() -> Lookahead {
        let margin = SpeculativeMargin::default();
        let step = PhysicsTimestep::default();
        Lookahead::new(Some(&margin), Some(&step), Some(&Gravity::EARTH_Z_UP))
    }

    const DYNAMIC: Moves = Moves::Dynamic {
        free: Vec3::ONE,
        asleep: false,
    };

    fn unit_box() -> BoundingVolume {
        BoundingVolume(Aabb::from_center_half_extents(Vec3::ZERO, Vec3::splat(0.5)))
    }

    #[test]
    fn two_bodies_resting_together_look_only_their_two_distances_ahead_within_1e_9() {
        // Side by side or stacked, at rest: gravity pulls both alike, so they close by nothing.
        let (l, bv) = (lookahead(), unit_box());
        let rest = l.motion(Some(&Velocity::default()), None, &bv, None, DYNAMIC);
        let d = SpeculativeMargin::default().distance;
        assert!((l.pair(&rest, &rest) - 2.0 * d).abs() < 1e-9);
        // The sum of their own bounds, the old rule, counted gravity twice.
        assert!(l.of(Some(&Velocity::default()), None, &bv, None) > d + 1e-3);
    }

    #[test]
    fn a_body_falling_on_an_unpulled_body_or_the_ground_counts_gravity_within_1e_6() {
        let (l, bv) = (lookahead(), unit_box());
        let v = Velocity(Vec3::new(0.0, 0.0, -2.0));
        let falling = l.motion(Some(&v), None, &bv, None, DYNAMIC);
        let dt = PhysicsTimestep::default().substep_dt();
        let d = SpeculativeMargin::default().distance;
        let closing = 2.0 * dt + 9.8 * dt * dt; // one substep: the farthest fall
        // A kinematic platform, a sleeping body and a paddle locked along gravity's axis are
        // not pulled (a game-written upward speed on the locked axis moves it neither).
        let rest = Some(&Velocity::default());
        let up = Velocity(Vec3::new(0.0, 0.0, 3.0));
        let sleeper = Moves::Dynamic {
            free: Vec3::ONE,
            asleep: true,
        };
        let locked = Moves::Dynamic {
            free: Vec3::new(1.0, 1.0, 0.0),
            asleep: false,
        };
        for other in [
            l.motion(rest, None, &bv, None, Moves::Kinematic),
            l.motion(rest, None, &bv, None, sleeper),
            l.motion(Some(&up), None, &bv, None, locked),
        ] {
            assert!((l.pair(&falling, &other) - (2.0 * d + closing)).abs() < 1e-6);
        }
        // The ground (static) has no distance of its own.
        let ground = BodyMotion::default();
        assert!((l.pair(&falling, &ground) - (d + closing)).abs() < 1e-6);
    }

    /// How far two point bodies close in one step of `n` symplectic Euler substeps (the
    /// solver's integration), each moved as `moves` says: the change of their separation.
    fn closed_by(l: &Lookahead, bodies: [(Vec3, f32, Moves); 2], n: u32) -> f32 {
        let h = l.dt / n as f32;
        let ends = bodies.map(|(v, scale, moves)| {
            let (moved, pulled) = moves.masks();
            let (mut x, mut v) = (Vec3::ZERO, v * moved);
            for _ in 0..n {
                v += l.gravity * scale * pulled * h;
                x += v * h;
            }
            x
        });
        (ends[0] - ends[1]).length()
    }

    #[test]
    fn a_pairs_margin_covers_how_far_the_solver_closes_them_is_symmetric_to_the_bit_and_finite() {
        // Random velocities, gravity scales and kinds (dynamic free or locked, asleep,
        // kinematic): the separation two bodies integrated like the solver's substeps change by
        // in a step is within the pair's margin less its fixed distances, unless the margin is
        // capped at what the broad phase grew them by (beyond a body's reach is CCD's business);
        // the margin does not depend on the pair's order.
        let mut rng = TestRng::new(5);
        for i in 0..10_000 {
            let n = [1, 2, 4, 8][i % 4];
            let l = lookahead().with_substeps(n);
            let body = |rng: &mut TestRng| {
                let v = Velocity(rng.vec3(-30.0, 30.0) * rng.range(0.0, 1.0).powi(3));
                let w = AngularVelocity(rng.vec3(-20.0, 20.0) * rng.range(0.0, 1.0).powi(3));
                let bv = BoundingVolume(Aabb::from_center_half_extents(
                    Vec3::ZERO,
                    rng.vec3(0.01, 3.0),
                ));
                let g = GravityScale(rng.range(-2.0, 3.0));
                let lock = |rng: &mut TestRng| if rng.unit() < 0.2 { 0.0 } else { 1.0 };
                let free = Vec3::new(lock(rng), lock(rng), lock(rng));
                let moves = match rng.below(4) {
                    0 => Moves::Kinematic,
                    1 => Moves::Dynamic { free, asleep: true },
                    _ => Moves::Dynamic {
                        free,
                        asleep: false,
                    },
                };
                let grown = l.of(Some(&v), Some(&w), &bv, Some(&g));
                let motion = l.motion(Some(&v), Some(&w), &bv, Some(&g), moves);
                (motion, grown, (v.0, g.0, moves))
            };
            let ((a, grown_a, pa), (b, grown_b, pb)) = (body(&mut rng), body(&mut rng));
            let m = l.pair(&a, &b);
            assert_eq!(m.to_bits(), l.pair(&b, &a).to_bits());
            assert!(m >= 0.0 && m.is_finite() && m <= grown_a + grown_b);
            let capped = m == grown_a + grown_b;
            let closed = closed_by(&l, [pa, pb], n);
            let room = m - a.distance - b.distance;
            assert!(
                capped || closed <= room * (1.0 + 1e-5) + 1e-7,
                "{n} substeps: {closed} > {room}"
            );
        }
    }
}

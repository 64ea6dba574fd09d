//! The knobs of a simulation, as resources. Each has a validated constructor: bad numbers are a
//! [`SettingsError`] at the call, never a panic or a silent NaN later.

use crate::dynamics::Integrator;
use crate::dynamics::response::SolverSettings;
use crate::dynamics::solver::SoftStepSettings;
#[cfg(feature = "ecs")]
use bevy_ecs::prelude::*;
use glam::Vec3;
use std::fmt;

/// Largest accepted step: beyond a second per step a game simulation has stopped meaning much.
pub const MAX_DT: f32 = 1.0;
/// Smallest accepted step (1 µs): Bevy's fixed clock counts in nanoseconds and refuses a zero
/// step (it panics), and a step below a microsecond rounds there.
pub const MIN_DT: f32 = 1e-6;
/// Most substeps accepted per step.
pub const MAX_SUBSTEPS: u32 = 1024;

/// Why a setting was refused.
#[derive(Clone, Debug, PartialEq)]
pub enum SettingsError {
    /// `dt` not finite, below [`MIN_DT`], or above [`MAX_DT`].
    BadTimestep(f32),
    /// Zero substeps or more than [`MAX_SUBSTEPS`].
    BadSubsteps(u32),
    /// A catch-up cap of zero steps.
    BadCatchUp(u32),
    /// A non-finite gravity vector.
    BadGravity(Vec3),
    /// A coefficient outside its range.
    BadCoefficient(&'static str, f32),
    /// A length unit not finite or outside [`LengthUnit::RANGE`].
    BadLengthUnit(f32),
}

impl fmt::Display for SettingsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadTimestep(dt) => {
                write!(
                    f,
                    "time step must be finite, >= {MIN_DT} s and <= {MAX_DT} s, got {dt}"
                )
            }
            Self::BadSubsteps(n) => write!(f, "substeps must be 1..={MAX_SUBSTEPS}, got {n}"),
            Self::BadCatchUp(n) => write!(f, "catch-up cap must be >= 1 step, got {n}"),
            Self::BadGravity(g) => write!(f, "gravity must be finite, got {g}"),
            Self::BadCoefficient(name, v) => write!(f, "{name} out of range: {v}"),
            Self::BadLengthUnit(u) => {
                let (lo, hi) = LengthUnit::RANGE;
                write!(
                    f,
                    "length unit must be finite, >= {lo} and <= {hi}, got {u}"
                )
            }
        }
    }
}

impl std::error::Error for SettingsError {}

/// The typical size of the scene's bodies, in the game's length unit (rapier's `length_unit`,
/// Box2D's `lengthUnitsPerMeter`, Avian's `PhysicsLengthUnit`). The thresholds that are lengths or
/// speeds are set for bodies about a metre across and read multiplied by it: the sleep speed
/// ([`SleepSettings::speed`], and with it the window a body must stay in), the soft-step solver's
/// restitution threshold, push-out speed, speed bound and warm-start distance
/// ([`SoftStepSettings`]), and the speculative margin's fixed distance. Everything else is already
/// in proportion to the bodies (the contacts' stiffness is a frequency, the margins follow the
/// motion). The lecture's legacy pipeline ([`ContactSettings::solver`]) keeps its metres.
///
/// Default 1. A scene of 1 cm dice and marbles in metres takes 0.01: with 1, a 1 cm ball
/// rolling one diameter a second fell asleep after half a diameter, and no drop below 5 cm
/// bounced (the threshold is 1 m/s); a game measuring in centimetres takes 100.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "ecs", derive(Resource))]
pub struct LengthUnit(f32);

impl Default for LengthUnit {
    fn default() -> Self {
        Self(1.0)
    }
}

impl LengthUnit {
    /// The sizes accepted: a micrometre to a thousand kilometres in metres (beyond, the scaled
    /// speed bound would near `f32`'s range).
    pub const RANGE: (f32, f32) = (1e-6, 1e6);

    /// Bodies about `size` across, in the game's unit.
    pub fn new(size: f32) -> Result<Self, SettingsError> {
        let (lo, hi) = Self::RANGE;
        if (lo..=hi).contains(&size) {
            Ok(Self(size))
        } else {
            Err(SettingsError::BadLengthUnit(size))
        }
    }

    /// The size.
    pub fn get(self) -> f32 {
        self.0
    }

    /// The soft-step solver's settings with their lengths and speeds in this unit.
    pub fn solver_settings(self, s: SoftStepSettings) -> SoftStepSettings {
        SoftStepSettings {
            max_push_out: s.max_push_out * self.0,
            restitution_threshold: s.restitution_threshold * self.0,
            warm_start_distance: s.warm_start_distance * self.0,
            max_linear_speed: s.max_linear_speed * self.0,
            ..s
        }
    }
}

/// The fixed step: `dt` seconds split into `substeps` equal substeps, and at most
/// `max_steps_per_frame` steps run per frame in an `App` ("the frame rate is sacred").
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "ecs", derive(Resource))]
pub struct PhysicsTimestep {
    dt: f32,
    substeps: u32,
    max_steps_per_frame: u32,
}

impl Default for PhysicsTimestep {
    /// 60 Hz, one substep, at most 4 steps per frame.
    fn default() -> Self {
        Self {
            dt: 1.0 / 60.0,
            substeps: 1,
            max_steps_per_frame: 4,
        }
    }
}

impl PhysicsTimestep {
    /// A step of `dt` seconds with `substeps` substeps.
    pub fn new(dt: f32, substeps: u32) -> Result<Self, SettingsError> {
        check_dt(dt)?;
        if substeps == 0 || substeps > MAX_SUBSTEPS {
            return Err(SettingsError::BadSubsteps(substeps));
        }
        Ok(Self {
            dt,
            substeps,
            ..Default::default()
        })
    }

    /// The same step with another catch-up cap.
    pub fn with_max_steps_per_frame(mut self, steps: u32) -> Result<Self, SettingsError> {
        if steps == 0 {
            return Err(SettingsError::BadCatchUp(steps));
        }
        self.max_steps_per_frame = steps;
        Ok(self)
    }

    /// Seconds per step.
    pub fn dt(&self) -> f32 {
        self.dt
    }

    /// Substeps per step.
    pub fn substeps(&self) -> u32 {
        self.substeps
    }

    /// Seconds per substep.
    pub fn substep_dt(&self) -> f32 {
        self.dt / self.substeps as f32
    }

    /// Most steps one frame may run.
    pub fn max_steps_per_frame(&self) -> u32 {
        self.max_steps_per_frame
    }

    /// Changes `dt` (e.g. to follow Bevy's fixed clock), refusing bad values.
    pub fn set_dt(&mut self, dt: f32) -> Result<(), SettingsError> {
        check_dt(dt)?;
        self.dt = dt;
        Ok(())
    }
}

fn check_dt(dt: f32) -> Result<(), SettingsError> {
    if dt.is_finite() && (MIN_DT..=MAX_DT).contains(&dt) {
        Ok(())
    } else {
        Err(SettingsError::BadTimestep(dt))
    }
}

/// Uniform gravitational acceleration (m/s²). Without this resource there is no gravity and the
/// gravity system does not run. The slides' value, z up: `(0, 0, -9.8)`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "ecs", derive(Resource))]
pub struct Gravity(Vec3);

impl Gravity {
    /// The slides' gravity, z up.
    pub const EARTH_Z_UP: Self = Self(Vec3::new(0.0, 0.0, -9.8));

    /// Gravity along any direction.
    pub fn new(acceleration: Vec3) -> Result<Self, SettingsError> {
        if acceleration.is_finite() {
            Ok(Self(acceleration))
        } else {
            Err(SettingsError::BadGravity(acceleration))
        }
    }

    /// The acceleration.
    pub fn acceleration(&self) -> Vec3 {
        self.0
    }
}

/// Which integrator advances the state (default: symplectic Euler).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "ecs", derive(Resource))]
pub struct Integration(pub Integrator);

/// How bodies turn. With `gyroscopic` on (the default) a free body keeps its angular
/// *momentum* — a box spun about its intermediate axis flips (the Dzhanibekov effect) — and
/// with it off it keeps its angular *velocity*, which is cheaper and is what engines that leave
/// the term out (rapier and Jolt by default) do. The integrator is the step's [`Integration`];
/// see [`crate::dynamics::rotation`] for how each method treats rotation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "ecs", derive(Resource))]
pub struct RotationSettings {
    /// Include the gyroscopic term `ω × Iω`.
    pub gyroscopic: bool,
}

impl Default for RotationSettings {
    fn default() -> Self {
        Self { gyroscopic: true }
    }
}

/// Contact response settings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "ecs", derive(Resource))]
pub struct ContactSettings {
    /// Restitution of bodies without a [`Restitution`](crate::components::Restitution).
    pub default_restitution: f32,
    /// Friction of bodies without a [`Friction`](crate::components::Friction).
    pub default_friction: f32,
    /// The contact solver's tunables.
    pub solver: SolverSettings,
}

impl Default for ContactSettings {
    fn default() -> Self {
        Self {
            default_restitution: 0.5,
            default_friction: 0.5,
            solver: SolverSettings::default(),
        }
    }
}

/// Sleeping (on by default): islands of bodies that stay still for `time` seconds (each within
/// `speed × time` of where its current window began, never faster than `4 × speed`) stop
/// being simulated until something wakes them (see
/// [`Sleeping`](crate::components::Sleeping) and [`crate::dynamics::islands`]): a sleeping
/// body is left out of every per-step pass (`benches/effects.rs`, group `sleeping`, measures
/// what a sleeping scene still costs). Turn it off (`enabled: false`) to watch a scene settle
/// for ever; turning it off wakes every sleeping body.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "ecs", derive(Resource))]
pub struct SleepSettings {
    /// Whether bodies may fall asleep.
    pub enabled: bool,
    /// The sleep speed (m/s for metre-sized bodies; read times the [`LengthUnit`]): a still body
    /// stays within `speed × time` of where its current window began (a net displacement: its
    /// average velocity below `speed`), its surface as it turns too, and moves slower than `4 ×
    /// speed` at every step (Jolt's sleep test with a cap; see [`crate::dynamics::stillness`]).
    /// Also the approach speed at which a contact wakes a sleeper.
    pub speed: f32,
    /// How long a body must stay still before it sleeps (s; more than 0).
    pub time: f32,
}

impl Default for SleepSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            speed: 0.05,
            time: 0.5,
        }
    }
}

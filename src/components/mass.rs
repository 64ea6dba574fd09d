//! How heavy a body is: by default from its colliders' volume at a density, as Avian's and
//! rapier's colliders give (a boulder outweighs a pebble without a line of code), or set by the
//! game. [`ComputedMass`] is what the solver uses; [`Mass`] and [`Density`] are what a game writes.
//!
//! The split follows Avian (`Mass` / `ColliderDensity` in, `ComputedMass` out): a required mass
//! component could not tell a mass the game chose from the default, so the one the game chooses
//! is optional and the derived one is required.

use bevy_ecs::lifecycle::HookContext;
use bevy_ecs::prelude::*;
use bevy_ecs::world::DeferredWorld;

/// The density (kg/m³) of a body without a [`Density`]: Avian's and rapier's default, so a
/// 1 m cube weighs 1 kg and a ball of radius 0.5 m about 0.52 kg.
pub const DEFAULT_DENSITY: f32 = 1.0;

/// A mass (kg) the game sets, overriding the one from the colliders' volume: finite and `> 0`
/// for dynamic bodies, [`Mass::INFINITE`] for kinematic ones. Zero, negative, subnormal or NaN
/// mass quarantines the body. Removing it brings back the mass from the volume.
///
/// Inserting one takes effect at once (a hook writes the body's [`ComputedMass`]), so a body
/// made kinematic or heavier by a game, even while a step runs or without the mass-properties
/// plugin, is never solved with its old mass; its inertia follows at the next step's Prepare.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[component(on_insert = take_mass_at_once)]
#[component(summary_tick)]
pub struct Mass(pub f32);

/// [`Mass`]'s insert hook: a valid mass becomes the body's [`ComputedMass`] now (an invalid
/// one is left to validation, which quarantines the body).
fn take_mass_at_once(mut world: DeferredWorld, ctx: HookContext) {
    let Some(&mass) = world.get::<Mass>(ctx.entity) else {
        return;
    };
    if let Some(mut computed) = world.get_mut::<ComputedMass>(ctx.entity)
        && mass.is_valid()
    {
        computed.0 = mass.0;
    }
}

impl Mass {
    /// A body no force or impulse can move.
    pub const INFINITE: Self = Self(f32::INFINITY);

    /// `1/m`, 0 for infinite mass.
    pub fn inverse(self) -> f32 {
        if self.0.is_infinite() {
            0.0
        } else {
            1.0 / self.0
        }
    }

    /// True for positive normal masses and for infinity (a subnormal mass has no finite
    /// inverse).
    pub fn is_valid(self) -> bool {
        self.0 > 0.0 && (self.0.is_normal() || self.0 == f32::INFINITY)
    }
}

/// The density (kg/m³) a body's mass is computed from, its parts' volumes included, when it has
/// no [`Mass`]: water is 1,000, steel about 7,850; [`DEFAULT_DENSITY`] without it. Recomputed
/// when a collider or part changes. A density that is not finite and positive is reported and
/// the default used instead.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[component(summary_tick)]
pub struct Density(pub f32);

/// The mass (kg) the solver uses, derived once per change (never every step): the body's [`Mass`]
/// if it has one, else its colliders' volume at its [`Density`]; 1 kg for a body without volume
/// (no collider, a half-space, shapes too small for an `f32` mass). Read it, do not write it:
/// set [`Mass`] or [`Density`] instead (a write is overwritten at the next change).
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct ComputedMass(pub(crate) f32);

impl Default for ComputedMass {
    fn default() -> Self {
        Self(1.0)
    }
}

impl ComputedMass {
    /// The mass in kg (infinite for a kinematic body).
    pub fn value(self) -> f32 {
        self.0
    }

    /// `1/m`, 0 for infinite mass.
    pub fn inverse(self) -> f32 {
        Mass(self.0).inverse()
    }

    /// The mass of a body from its explicit `mass`, else from its volume at `density`
    /// (`unit_volume_mass` being its mass at 1 kg/m³); `Err` carries the density that gave no
    /// usable mass (the default one is used then).
    pub(crate) fn derive(
        mass: Option<Mass>,
        density: Option<Density>,
        unit_volume_mass: f32,
    ) -> (Self, Result<(), f32>) {
        if let Some(Mass(m)) = mass {
            return (Self(m), Ok(()));
        }
        let rho = density.map_or(DEFAULT_DENSITY, |d| d.0);
        let at = |rho: f32| Some(rho * unit_volume_mass).filter(|m| m.is_normal() && *m > 0.0);
        match (at(rho), at(DEFAULT_DENSITY)) {
            (Some(m), _) => (Self(m), Ok(())),
            // The density gives no usable mass where the default one does.
            (None, Some(m)) => (Self(m), Err(rho)),
            // No usable volume, whatever the density.
            (None, None) => (Self(1.0), Ok(())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_explicit_mass_wins_then_the_density_then_the_default_density() {
        let derive = |m, d, v| ComputedMass::derive(m, d, v);
        assert_eq!(
            derive(Some(Mass(3.0)), Some(Density(9.0)), 2.0),
            (ComputedMass(3.0), Ok(()))
        );
        assert_eq!(
            derive(Some(Mass::INFINITE), None, 2.0).0,
            ComputedMass(f32::INFINITY)
        );
        assert_eq!(
            derive(None, Some(Density(500.0)), 0.5),
            (ComputedMass(250.0), Ok(()))
        );
        assert_eq!(derive(None, None, 0.5), (ComputedMass(0.5), Ok(())));
    }

    #[test]
    fn a_bad_density_is_reported_and_no_volume_weighs_1_kg() {
        let derive = |d, v| ComputedMass::derive(None, d, v);
        let (nan, report) = derive(Some(Density(f32::NAN)), 0.5);
        assert!(nan == ComputedMass(0.5) && report.is_err_and(f32::is_nan));
        // Overflow (1e30 × 1e10) too.
        assert_eq!(
            derive(Some(Density(1e30)), 1e10),
            (ComputedMass(1e10), Err(1e30))
        );
        for bad in [0.0, -2.0, f32::INFINITY] {
            assert_eq!(
                derive(Some(Density(bad)), 0.5),
                (ComputedMass(0.5), Err(bad))
            );
        }
        // No collider or an unbounded one (0 or infinite volume), a vanishing shape: 1 kg.
        for volume in [0.0, f32::INFINITY, 1e-45] {
            assert_eq!(derive(None, volume), (ComputedMass(1.0), Ok(())));
        }
        // A huge density over a tiny shape is fine.
        assert_eq!(
            derive(Some(Density(1e30)), 1e-20),
            (ComputedMass(1e10), Ok(()))
        );
    }

    #[test]
    fn subnormal_and_non_positive_masses_are_invalid_and_infinity_is_valid() {
        for bad in [0.0, -1.0, 1e-40, f32::NAN, f32::NEG_INFINITY] {
            assert!(!Mass(bad).is_valid(), "{bad}");
        }
        for good in [1e-30, 1.0, 1e30, f32::INFINITY] {
            assert!(Mass(good).is_valid(), "{good}");
        }
    }
}

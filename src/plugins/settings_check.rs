//! Settings resources are checked where game code can change them: at the start of each step,
//! when one changed. A setting with an unusable value (a NaN sleep speed put every body to
//! sleep in mid-air; a negative friction reversed it) is refused: the resource goes back to its
//! defaults and a warning names the value. The fields stay public, as Bevy resources' fields
//! are; the rule for each is written once here.

use crate::plugins::ccd::CcdSettings;
use crate::plugins::soft_step::SpeculativeMargin;
use crate::settings::{ContactSettings, SleepSettings};
use bevy_ecs::component::Mutable;
use bevy_ecs::prelude::*;

/// The rule of a settings resource: what, if anything, makes its values unusable.
pub(crate) trait SettingsRule: Resource + Component<Mutability = Mutable> + Default {
    /// The first unusable value, described; `None` when every value is usable.
    fn problem(&self) -> Option<String>;
}

/// `Some(description)` when `x` is not finite or below `min`.
fn below(name: &str, x: f32, min: f32) -> Option<String> {
    (!(x.is_finite() && x >= min)).then(|| format!("{name} must be finite and >= {min}, got {x}"))
}

/// `Some(description)` when `x` is not finite or not above `min`.
fn not_above(name: &str, x: f32, min: f32) -> Option<String> {
    (!(x.is_finite() && x > min)).then(|| format!("{name} must be finite and > {min}, got {x}"))
}

impl SettingsRule for ContactSettings {
    fn problem(&self) -> Option<String> {
        let s = &self.solver;
        below("default_restitution", self.default_restitution, 0.0)
            .or_else(|| below("default_friction", self.default_friction, 0.0))
            .or_else(|| below("solver.restitution_threshold", s.restitution_threshold, 0.0))
            .or_else(|| below("solver.slop", s.slop, 0.0))
            .or_else(|| below("solver.correction_fraction", s.correction_fraction, 0.0))
            .or_else(|| {
                (s.correction_fraction > 1.0).then(|| {
                    format!(
                        "solver.correction_fraction must be <= 1, got {}",
                        s.correction_fraction
                    )
                })
            })
    }
}

impl SettingsRule for SleepSettings {
    fn problem(&self) -> Option<String> {
        // A zero time would put every body to sleep at its first step, in mid-air too.
        below("speed", self.speed, 0.0).or_else(|| not_above("time", self.time, 0.0))
    }
}

impl SettingsRule for SpeculativeMargin {
    fn problem(&self) -> Option<String> {
        below("distance", self.distance, 0.0)
            .or_else(|| below("reach_ratio", self.reach_ratio, 0.0))
    }
}

impl SettingsRule for CcdSettings {
    fn problem(&self) -> Option<String> {
        self.auto_speed_ratio.and_then(|r| {
            (!(r.is_finite() && r > 0.0))
                .then(|| format!("auto_speed_ratio must be finite and > 0 (or None), got {r}"))
        })
    }
}

/// Refuses unusable values of `S` written since the last step: back to the defaults, with a
/// warning.
pub(crate) fn check_settings<S: SettingsRule>(settings: Option<ResMut<S>>) {
    let Some(mut settings) = settings.filter(|s| s.is_changed()) else {
        return;
    };
    if let Some(problem) = settings.problem() {
        log::warn!(
            "urto: {} refused ({problem}); using the defaults",
            std::any::type_name::<S>()
        );
        *settings = S::default();
    }
}

//! What the step did: wall time per stage, how often each effect ran, and named counters.
//!
//! Systems record here; the rerun plugin and tests read. It is how "simulate only the effects a
//! scene calls for" is *measured*: an effect whose run condition is false never bumps its count.

use bevy_ecs::prelude::*;
use std::time::{Duration, Instant};

/// The stages of a step, in schedule order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Validation and poses.
    Prepare,
    /// Force gathering.
    Forces,
    /// Integration (summed over substeps).
    Integrate,
    /// Bounding volumes and pairs (summed over substeps).
    BroadPhase,
    /// Contacts (summed over substeps).
    NarrowPhase,
    /// Response (summed over substeps).
    Response,
    /// Recording.
    Debug,
}

impl Stage {
    /// All stages in order.
    pub const ALL: [Stage; 7] = [
        Stage::Prepare,
        Stage::Forces,
        Stage::Integrate,
        Stage::BroadPhase,
        Stage::NarrowPhase,
        Stage::Response,
        Stage::Debug,
    ];

    /// Lower-case name, used as the rerun entity path `timing/<name>`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Prepare => "prepare",
            Self::Forces => "forces",
            Self::Integrate => "integrate",
            Self::BroadPhase => "broad_phase",
            Self::NarrowPhase => "narrow_phase",
            Self::Response => "response",
            Self::Debug => "debug",
        }
    }
}

/// Per-step statistics of the physics.
#[derive(Resource, Debug, Default, Clone)]
pub struct PhysicsStats {
    /// Steps completed.
    pub step: u64,
    /// Simulated seconds completed.
    pub sim_time: f64,
    stage_time: [Duration; 7],
    runs: Vec<(&'static str, u64)>,
    counters: Vec<(&'static str, f64)>,
    /// Counters that sum the work of the step's substeps (see [`PhysicsStats::add_counter`]).
    summed: Vec<&'static str>,
}

impl PhysicsStats {
    /// Clears the per-step timings (called at the start of a step).
    pub fn begin_step(&mut self) {
        self.stage_time = Default::default();
        for (name, value) in &mut self.counters {
            if self.summed.contains(name) {
                *value = 0.0;
            }
        }
    }

    /// Wall time spent in `stage` during the last step.
    pub fn stage_time(&self, stage: Stage) -> Duration {
        self.stage_time[stage as usize]
    }

    /// Adds wall time to a stage.
    pub fn add_time(&mut self, stage: Stage, t: Duration) {
        self.stage_time[stage as usize] += t;
    }

    /// Runs `f`, charging its wall time to `stage` and counting one run of `effect`.
    pub fn time<R>(&mut self, stage: Stage, effect: &'static str, f: impl FnOnce() -> R) -> R {
        let start = Instant::now();
        let r = f();
        self.add_time(stage, start.elapsed());
        self.count_run(effect);
        r
    }

    /// Counts one run of an effect (a system that did work).
    pub fn count_run(&mut self, effect: &'static str) {
        match self.runs.iter_mut().find(|(n, _)| *n == effect) {
            Some((_, c)) => *c += 1,
            None => self.runs.push((effect, 1)),
        }
    }

    /// How many times `effect` has run since the world began.
    pub fn runs(&self, effect: &str) -> u64 {
        self.runs
            .iter()
            .find(|(n, _)| *n == effect)
            .map_or(0, |(_, c)| *c)
    }

    /// Sets a named counter of the last step (e.g. `"broad_phase/pairs"`): with substeps, the
    /// last substep's value.
    pub fn set_counter(&mut self, name: &'static str, value: f64) {
        match self.counters.iter_mut().find(|(n, _)| *n == name) {
            Some((_, v)) => *v = value,
            None => self.counters.push((name, value)),
        }
    }

    /// Adds to a named counter that sums the work of all the step's substeps (e.g.
    /// `"ccd/impacts"`); it restarts from zero each step, so a step without that work reads 0.
    pub fn add_counter(&mut self, name: &'static str, value: f64) {
        match self.counters.iter_mut().find(|(n, _)| *n == name) {
            Some((_, v)) => *v += value,
            None => {
                self.counters.push((name, value));
                self.summed.push(name);
            }
        }
    }

    /// A named counter's value, if ever set.
    pub fn counter(&self, name: &str) -> Option<f64> {
        self.counters
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| *v)
    }

    /// All counters, in the order they were first set (deterministic).
    pub fn counters(&self) -> &[(&'static str, f64)] {
        &self.counters
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summed_counters_add_over_substeps_and_restart_each_step() {
        let mut stats = PhysicsStats::default();
        stats.set_counter("pairs", 7.0);
        stats.add_counter("impacts", 2.0);
        stats.add_counter("impacts", 3.0);
        assert_eq!(stats.counter("impacts"), Some(5.0));
        stats.begin_step();
        assert_eq!(stats.counter("impacts"), Some(0.0));
        assert_eq!(
            stats.counter("pairs"),
            Some(7.0),
            "a set counter keeps its last value"
        );
    }
}

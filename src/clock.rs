//! The fixed-step clock: the slides' main loop with an accumulator.
//!
//! `simulate(dt)` must not depend on CPU speed, and "the frame rate is sacred": a frame that took
//! long must not make the next frame simulate so many steps that it takes even longer (the
//! spiral of death). The clock turns frame times into a whole number of fixed steps, carrying the
//! remainder to the next frame, and drops simulated time beyond `max_steps_per_frame` steps.

/// Turns variable frame times into fixed steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedStepClock {
    dt: f64,
    max_steps_per_frame: u32,
    accumulator: f64,
    dropped: f64,
}

/// What one frame should simulate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StepPlan {
    /// Fixed steps to run now.
    pub steps: u32,
    /// True when the cap dropped simulated time this frame.
    pub capped: bool,
}

impl FixedStepClock {
    /// A clock of step `dt` seconds running at most `max_steps_per_frame` steps per frame.
    /// `None` for `dt` that is not finite and positive or a cap of zero.
    pub fn new(dt: f64, max_steps_per_frame: u32) -> Option<Self> {
        (dt.is_finite() && dt > 0.0 && max_steps_per_frame > 0).then_some(Self {
            dt,
            max_steps_per_frame,
            accumulator: 0.0,
            dropped: 0.0,
        })
    }

    /// Adds a frame's elapsed time and says how many steps to run. Negative or non-finite frame
    /// times count as zero.
    pub fn advance(&mut self, frame_time: f64) -> StepPlan {
        if frame_time.is_finite() && frame_time > 0.0 {
            self.accumulator += frame_time;
        }
        let due = (self.accumulator / self.dt).floor();
        let steps = due.min(self.max_steps_per_frame as f64) as u32;
        self.accumulator -= steps as f64 * self.dt;
        let capped = due > steps as f64;
        if capped {
            // Keep the fraction of a step, drop whole steps we will never catch up on.
            let keep = self.accumulator % self.dt;
            self.dropped += self.accumulator - keep;
            self.accumulator = keep;
        }
        StepPlan { steps, capped }
    }

    /// The fixed step.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Time carried to the next frame (always `< dt` after [`advance`](Self::advance)).
    pub fn pending(&self) -> f64 {
        self.accumulator
    }

    /// Simulated time dropped so far by the cap.
    pub fn dropped(&self) -> f64 {
        self.dropped
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_follow_elapsed_time_not_frame_count() {
        let mut c = FixedStepClock::new(0.01, 100).unwrap();
        let total: u32 = [0.004, 0.004, 0.004, 0.0125, 0.0255]
            .iter()
            .map(|&t| c.advance(t).steps)
            .sum();
        assert_eq!(total, 5); // 0.05 s of frames = 5 steps of 0.01 s
        assert!(c.pending() < 0.01);
    }

    #[test]
    fn a_long_frame_is_capped_and_the_excess_dropped() {
        let mut c = FixedStepClock::new(1.0 / 60.0, 4).unwrap();
        let plan = c.advance(1.0);
        assert_eq!(
            plan,
            StepPlan {
                steps: 4,
                capped: true
            }
        );
        assert!(c.pending() < c.dt());
        assert!((c.dropped() + c.pending() + 4.0 * c.dt() - 1.0).abs() < 1e-9);
        assert_eq!(c.advance(1.0 / 60.0).steps, 1);
    }

    #[test]
    fn bad_settings_and_frame_times_are_refused_or_ignored() {
        assert!(FixedStepClock::new(0.0, 1).is_none());
        assert!(FixedStepClock::new(-0.1, 1).is_none());
        assert!(FixedStepClock::new(f64::NAN, 1).is_none());
        assert!(FixedStepClock::new(0.1, 0).is_none());
        let mut c = FixedStepClock::new(0.1, 3).unwrap();
        assert_eq!(c.advance(f64::NAN).steps, 0);
        assert_eq!(c.advance(-5.0).steps, 0);
    }
}

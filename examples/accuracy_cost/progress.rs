//! The progress bar: one tick per unit of work (a run, a measurement), with the current task.

use indicatif::{ProgressBar, ProgressStyle};

/// A progress bar over a known number of work units.
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// A bar of `total` units.
    pub fn new(total: u64) -> Self {
        let bar = ProgressBar::new(total);
        // The template is a constant, so parsing cannot fail in practice; fall back to the
        // default style rather than panic if it ever did.
        if let Ok(style) =
            ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} {msg}")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        Self { bar }
    }

    /// Names the task now running.
    pub fn task(&self, what: impl Into<String>) {
        self.bar.set_message(what.into());
    }

    /// One unit done.
    pub fn tick(&self) {
        self.bar.inc(1);
    }

    /// Clears the bar at the end.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

//! The rerun recording of the report's series: each experiment on its own timeline, one
//! `Scalars` entity per line of its plots. Values are converted to rerun's types here, at the
//! boundary; the sections only hand over `(time, value)` pairs.

use rerun::RecordingStream;
use std::error::Error;
use std::path::Path;

/// A `.rrd` file being written.
pub struct Recording {
    stream: RecordingStream,
}

/// Where a series sits on its timeline.
#[derive(Clone, Copy, Debug)]
pub enum Time {
    /// An ordinal (an index, a substep count, a bounce number).
    Sequence(i64),
    /// Simulated seconds.
    Seconds(f64),
}

impl Recording {
    /// Starts a recording saved to `path`.
    pub fn create(path: &Path) -> Result<Self, Box<dyn Error>> {
        let stream = rerun::RecordingStreamBuilder::new("urto_accuracy_cost").save(path)?;
        Ok(Self { stream })
    }

    /// Logs `points` as a time series `entity` on `timeline`. Non-finite values are skipped
    /// (rerun would draw them as gaps anyway, and the report treats them as "diverged").
    pub fn series(
        &self,
        timeline: &'static str,
        entity: &str,
        points: impl IntoIterator<Item = (Time, f64)>,
    ) {
        // Only this experiment's timeline is set, so series do not leak onto other timelines.
        self.stream.reset_time();
        for (t, value) in points {
            if !value.is_finite() {
                continue;
            }
            match t {
                Time::Sequence(i) => self.stream.set_time_sequence(timeline, i),
                Time::Seconds(s) => self.stream.set_duration_secs(timeline, s),
            }
            if let Err(e) = self.stream.log(entity, &rerun::Scalars::single(value)) {
                eprintln!("rerun: could not log {entity}: {e}");
            }
        }
    }

    /// Writes what is buffered to the file.
    pub fn flush(&self) -> Result<(), Box<dyn Error>> {
        self.stream.flush_blocking()?;
        Ok(())
    }
}

/// A name fit for an entity path: lower case, words joined by `_`.
pub fn slug(name: &str) -> String {
    let mut out = String::new();
    for c in name.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.ends_with('_') {
            out.push('_');
        }
    }
    out.trim_matches('_').to_string()
}

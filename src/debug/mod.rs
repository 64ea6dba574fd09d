//! Debug output: consumers at the end of the step that read and never write physics state.

#[cfg(feature = "rerun")]
pub mod rerun;
#[cfg(feature = "rerun")]
pub use self::rerun::{DebugColor, RecordingSink, RerunConfig, RerunDebugPlugin, RerunError};

//! Shared set-up for the integration tests (included with `mod common;`).
#![allow(dead_code)]

use bevy_app::App;
use urto::prelude::*;

/// An app with every urto stage and the given step.
pub fn app_with(dt: f32, substeps: u32) -> App {
    let mut app = App::new();
    app.add_plugins(UrtoPlugins::with_timestep(
        PhysicsTimestep::new(dt, substeps).expect("valid test timestep"),
    ));
    app
}

/// An app at 60 Hz, one substep.
pub fn app() -> App {
    app_with(1.0 / 60.0, 1)
}

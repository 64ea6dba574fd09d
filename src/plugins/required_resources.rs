//! Resources the stages cannot run without, made again when game code removes one.
//!
//! Removing a resource at any time is input too: a system whose `Res<T>` is gone would make
//! Bevy panic. Each plugin registers the resources it owns here, with how to make each one (its
//! defaults, or the value the plugin was built with), and the first system of every step puts
//! back any that went missing, with a warning that names it. Switching a stage off is done by
//! disabling its plugin, never by removing its resources.

use bevy_app::App;
use bevy_ecs::prelude::*;

/// One required resource: its name, whether it is present, and how to make it again.
struct Required {
    name: &'static str,
    present: fn(&World) -> bool,
    make: Box<dyn Fn(&mut World) + Send + Sync>,
}

/// The resources registered by the plugins, checked at the start of every step.
#[derive(Resource, Default)]
pub(crate) struct RequiredResources(Vec<Required>);

/// How a plugin registers the resources it owns.
pub(crate) trait RequireResource {
    /// Inserts `make()` now and registers it to be made again if it goes missing.
    fn insert_required<R: Resource>(
        &mut self,
        make: impl Fn() -> R + Send + Sync + 'static,
    ) -> &mut Self;

    /// Inits `R` from its defaults (keeping one already there) and registers it.
    fn init_required<R: Resource + Default>(&mut self) -> &mut Self;
}

impl RequireResource for App {
    fn insert_required<R: Resource>(
        &mut self,
        make: impl Fn() -> R + Send + Sync + 'static,
    ) -> &mut Self {
        self.insert_resource(make());
        register::<R>(self, make);
        self
    }

    fn init_required<R: Resource + Default>(&mut self) -> &mut Self {
        self.init_resource::<R>();
        register::<R>(self, R::default);
        self
    }
}

fn register<R: Resource>(app: &mut App, make: impl Fn() -> R + Send + Sync + 'static) {
    let world = app.world_mut();
    let mut list = world.get_resource_or_insert_with(RequiredResources::default);
    let name = std::any::type_name::<R>();
    if list.0.iter().any(|r| r.name == name) {
        return;
    }
    list.0.push(Required {
        name,
        present: |w| w.contains_resource::<R>(),
        make: Box::new(move |w| w.insert_resource(make())),
    });
}

/// Puts back every required resource that game code removed, warning once for each. Every
/// step pays only the presence checks; the list leaves the world only when one is missing.
pub(crate) fn restore_required_resources(world: &mut World) {
    let missing = world
        .get_resource::<RequiredResources>()
        .is_some_and(|list| list.0.iter().any(|r| !(r.present)(world)));
    if !missing {
        return;
    }
    let Some(list) = world.remove_resource::<RequiredResources>() else {
        return;
    };
    for r in &list.0 {
        if !(r.present)(world) {
            log::warn!(
                "urto: resource {} was removed while physics runs; it is made again (disable \
                 its plugin to switch a stage off)",
                r.name
            );
            (r.make)(world);
        }
    }
    world.insert_resource(list);
}

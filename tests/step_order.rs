//! The step runs its stages in the documented order, substeps included.

mod common;

use bevy_ecs::prelude::*;
use urto::prelude::*;

#[derive(Resource, Default)]
struct Trace(Vec<&'static str>);

fn probe(name: &'static str) -> impl FnMut(ResMut<Trace>) {
    move |mut t: ResMut<Trace>| t.0.push(name)
}

#[test]
fn stages_run_in_schedule_order_with_substeps_inside() {
    let mut app = common::app_with(1.0 / 60.0, 3);
    app.init_resource::<Trace>()
        .add_systems(
            PhysicsSchedule,
            probe("prepare").in_set(PhysicsSet::Prepare),
        )
        .add_systems(PhysicsSchedule, probe("forces").in_set(PhysicsSet::Forces))
        .add_systems(PhysicsSchedule, probe("debug").in_set(PhysicsSet::Debug))
        .add_systems(
            SubstepSchedule,
            probe("integrate").in_set(SubstepSet::Integrate),
        )
        .add_systems(
            SubstepSchedule,
            probe("broad").in_set(SubstepSet::BroadPhase),
        )
        .add_systems(
            SubstepSchedule,
            probe("narrow").in_set(SubstepSet::NarrowPhase),
        )
        .add_systems(
            SubstepSchedule,
            probe("response").in_set(SubstepSet::Response),
        );
    urto::step(app.world_mut(), 2).unwrap();
    let substep = ["integrate", "broad", "narrow", "response"];
    let mut one_step = vec!["prepare", "forces"];
    for _ in 0..3 {
        one_step.extend(substep);
    }
    one_step.push("debug");
    let expected: Vec<_> = one_step.iter().chain(one_step.iter()).copied().collect();
    assert_eq!(app.world().resource::<Trace>().0, expected);
    let stats = app.world().resource::<PhysicsStats>();
    assert_eq!(stats.step, 2);
    assert!((stats.sim_time - 2.0 / 60.0).abs() < 1e-6);
}

#[test]
fn stepping_a_world_without_the_plugins_is_an_error_not_a_panic() {
    let mut world = World::new();
    assert_eq!(
        urto::step(&mut world, 1),
        Err(urto::plugins::StepError::NoPhysicsSchedule)
    );
}

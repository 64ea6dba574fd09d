//! The still group without the settled bodies' revision: game code removed the resource (it
//! comes back at the next step, with a value never used before), and the queries read the
//! settled colliders at each refresh meanwhile.

use super::*;
use crate::plugins::UrtoPlugins;
use bevy_ecs::system::RunSystemOnce;

/// The nearest hit of a ray down the z axis at `x`, after a refresh if `refresh`.
fn hit_at(app: &mut App, x: f32, refresh: bool) -> Option<Entity> {
    app.world_mut()
        .run_system_once(move |q: SpatialQuery| {
            if refresh {
                q.refresh();
            }
            let all = SpatialQueryFilter::default();
            let hit = q.cast_ray(Vec3::new(x, 0.0, 10.0), -Vec3::Z, 100.0, &all);
            hit.ok().flatten().map(|h| h.entity)
        })
        .unwrap_or(None)
}

#[test]
fn settled_statics_moved_while_their_revision_is_removed_are_hit_where_they_are_5_times() {
    let mut app = App::new();
    app.add_plugins(UrtoPlugins::default());
    let blocks: Vec<Entity> = (0..5)
        .map(|i| {
            let at = Position(Vec3::new(3.0 * i as f32, 0.0, 0.0));
            let block = (Collider::cuboid(0.5, 0.5, 0.5), at, Static);
            app.world_mut().spawn(block).id()
        })
        .collect();
    crate::step(app.world_mut(), 2).unwrap_or_default();
    assert_eq!(hit_at(&mut app, 0.0, false), Some(blocks[0]));
    let reads = |app: &App| app.world().resource::<SpatialQueryIndex>().refreshes();
    let before = reads(&app).still_reads;
    for (i, &block) in blocks.iter().enumerate() {
        let x = 3.0 * i as f32;
        let world = app.world_mut();
        assert!(world.remove_resource::<StillRevision>().is_some());
        // Still settled: moved between steps and seen after a refresh.
        world
            .entity_mut(block)
            .insert(Position(Vec3::new(x, 20.0, 0.0)));
        assert_eq!(hit_at(&mut app, x, true), None, "block {i} moved away");
        // Put back after its step's check, settled again: found where it is.
        app.world_mut()
            .entity_mut(block)
            .insert(Position(Vec3::new(x, 0.0, 0.0)));
        crate::step(app.world_mut(), 1).unwrap_or_default();
        assert_eq!(hit_at(&mut app, x, false), Some(block), "block {i} back");
    }
    assert!(reads(&app).still_reads >= before + 10, "{:?}", reads(&app));
}

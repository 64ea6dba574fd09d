//! The viewer's layout: the blueprint the recording opens with.

use super::RerunConfig;

/// The layout the viewer opens on: the 3D scene large on the left; on the right the wall time
/// of each stage in one plot and the step's counters in another (instead of one plot each).
/// With per-level views asked for (hierarchy levels, scene-graph levels) they sit as tabs on top
/// of the right column, and the main scene leaves the level boxes out; with grid cells asked
/// for, the close-up of the moving bodies and their cells takes the main view's place and the
/// whole scene becomes the first tab.
/// The time panel starts collapsed (the scene gets the room); with
/// [`RerunConfig::open_at_end`] the viewer shows the last recorded step.
pub(super) fn default_layout(config: &RerunConfig) -> rerun::blueprint::Blueprint {
    use rerun::blueprint::components::{PanelState, PlayState};
    use rerun::blueprint::*;
    let scene = Spatial3DView::new("scene").with_origin("/").with_contents([
        "+ /**",
        "- /hierarchy/**",
        "- /scene_graph/**",
        "+ /scene_graph/visited/**",
    ]);
    let timing = TimeSeriesView::new("time per stage (ms)").with_origin("/timing");
    let counters = TimeSeriesView::new("counters").with_origin("/counters");
    let log = TextLogView::new("log").with_origin("/log");
    let mut tabs = detail_views(config);
    // With grid cells asked for, the close-up of the moving bodies is the main view and the
    // whole scene (a town is mostly far from its cars) the first tab.
    let main = if config.grid_cells {
        std::mem::replace(&mut tabs[0], scene.into())
    } else {
        scene.into()
    };
    let side = if tabs.is_empty() {
        Vertical::new([timing.into(), counters.into(), log.into()]).with_row_shares([0.4, 0.4, 0.2])
    } else {
        Vertical::new([
            Tabs::new(tabs).into(),
            timing.into(),
            counters.into(),
            log.into(),
        ])
        .with_row_shares([0.45, 0.22, 0.23, 0.1])
    };
    let mut time_panel = TimePanel::new().with_state(PanelState::Collapsed);
    if config.open_at_end {
        time_panel = time_panel.with_play_state(PlayState::Following);
    }
    Blueprint::new(Horizontal::new([main, side.into()]).with_column_shares([0.6, 0.4]))
        .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
        .with_time_panel(time_panel)
}

/// The tabbed views of the right column: a close-up of the moving bodies and their grid cells,
/// then one view per scene-graph level, then one per mesh-hierarchy level.
fn detail_views(config: &RerunConfig) -> Vec<rerun::blueprint::ContainerLike> {
    use rerun::blueprint::Spatial3DView;
    let mut views = Vec::new();
    if config.grid_cells {
        // Only the moving bodies and what the grid says about them: the viewer frames the view
        // on them, not on the whole static scene.
        let close_up = Spatial3DView::new("grid cells")
            .with_origin("/")
            .with_contents([
                "+ /world",
                "+ /world/bodies/**",
                "+ /world/contacts",
                "+ /broad_phase/grid_cells/**",
                "+ /broad_phase/candidates/**",
            ]);
        views.push(close_up.into());
    }
    for k in 0..config.scene_graph_levels {
        let level = Spatial3DView::new(format!("scene graph level {k}"))
            .with_origin("/")
            .with_contents([
                "+ /world/**".to_owned(),
                "- /world/bounding_volumes".to_owned(),
                "- /world/velocities".to_owned(),
                format!("+ /scene_graph/level_{k}/**"),
            ]);
        views.push(level.into());
    }
    for k in 0..config.bvh_levels {
        let level = Spatial3DView::new(format!("BVH level {k}"))
            .with_origin("/")
            .with_contents([
                "+ /world/meshes/**".to_owned(),
                format!("+ /hierarchy/level_{k}/**"),
            ]);
        views.push(level.into());
    }
    views
}

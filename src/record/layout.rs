//! The viewer layout of each pipeline's recording.

use super::paths::{self, origin};
use crate::pipelines::Kind;

/// The viewer layout: the 3D scene large on the left; on the right the
/// pipeline's series (θ-PSO cost terms; FLATLO airspeeds and load factors;
/// the fleet's inter-agent distances, Fig. 13), its events, and the mission
/// file. A pipeline's recording starts with its own layout (so its log
/// lines show from the first), the scene alone with θ-PSO's.
pub fn layout(kind: Kind) -> rerun::blueprint::Blueprint {
    use rerun::blueprint::{
        Blueprint, BlueprintPanel, ContainerLike, Horizontal, SelectionPanel, Spatial3DView, Tabs,
        TextDocumentView, TextLogView, TimePanel, TimeSeriesView, Vertical,
    };
    // The pipeline's plots (`Pipeline::plots`), a panel of several as tabs.
    let series: Vec<ContainerLike> = kind
        .face()
        .plots()
        .iter()
        .map(|panel| {
            let views = panel.iter().map(|plot| {
                ContainerLike::from(TimeSeriesView::new(plot.title).with_origin(origin(plot.path)))
            });
            match panel {
                [_] => views.collect::<Vec<_>>().remove(0),
                _ => Tabs::new(views).into(),
            }
        })
        .collect();
    let mut column = series;
    column.push(
        TextLogView::new("events")
            .with_origin(origin(&paths::root(kind)))
            .into(),
    );
    column.push(
        TextDocumentView::new("mission")
            .with_origin(origin(paths::MISSION))
            .into(),
    );
    Blueprint::new(
        Horizontal::new([
            Spatial3DView::new("scene").with_origin("/").into(),
            Vertical::new(column).into(),
        ])
        .with_column_shares([2.0, 1.0]),
    )
    // The scene gets the room: the blueprint tree and the selection panel
    // start folded away (the viewer's menu brings them back).
    .with_blueprint_panel(
        BlueprintPanel::new().with_state(rerun::blueprint::components::PanelState::Collapsed),
    )
    .with_selection_panel(
        SelectionPanel::new().with_state(rerun::blueprint::components::PanelState::Collapsed),
    )
    .with_time_panel(TimePanel::new().with_timeline("sim_time"))
}

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
    let series: Vec<ContainerLike> = match kind {
        // The clearance plays with the flight on `sim_time`, the timeline
        // the viewer opens on; the cost is on `iteration`, in the tab behind.
        Kind::ThetaPso => vec![
            Tabs::new([
                TimeSeriesView::new("clearance to obstacles, m")
                    .with_origin(origin(paths::theta_pso::CLEARANCE))
                    .into(),
                TimeSeriesView::new("θ-PSO cost (timeline: iteration)")
                    .with_origin(origin(paths::theta_pso::COST))
                    .into(),
            ])
            .into(),
        ],
        Kind::Flatlo => vec![
            TimeSeriesView::new("airspeed, m/s")
                .with_origin(origin(paths::flatlo::AIRSPEED))
                .into(),
            TimeSeriesView::new("load factor")
                .with_origin(origin(paths::flatlo::LOAD_FACTOR))
                .into(),
        ],
        Kind::Fleet => vec![
            TimeSeriesView::new("inter-agent distances, m (Fig. 13)")
                .with_origin(origin(paths::fleet::DISTANCES))
                .into(),
        ],
    };
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

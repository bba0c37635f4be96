//! Everything that can happen in the TUI, as data.
//!
//! Keys and mouse events become actions (`input.rs`); `App::update` is the
//! only place state changes. Tests drive the app with actions directly.

use nalgebra::Point2;

use super::fields::Item;
use crate::pipelines::Kind;

/// Which panel takes the keys that are not global.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Focus {
    Map,
    Inspector,
    Jobs,
}

/// What the large left pane shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pane {
    Map,
    Formation,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    /// Quit, asking first when there are unsaved changes.
    Quit,
    ToggleHelp,
    /// Scroll the help overlay by this many lines.
    ScrollHelp(i32),
    /// Clear the text of a prompt (Ctrl-u).
    PromptClear,
    /// Close the overlay (or cancel the prompt) on top.
    Dismiss,
    FocusNext,
    FocusPrevious,
    FocusOn(Focus),
    /// Left pane: the map.
    ShowMap,
    /// Left pane: the formation editor.
    ShowFormation,
    ToggleSideView,

    SelectNext,
    SelectPrevious,
    Select(Item),
    /// Move the selection by whole steps (east, north on the map; forward,
    /// left in the formation editor).
    Nudge(f64, f64),
    /// Grow (+1) or shrink (-1) the nudge step.
    ChangeStep(i32),

    /// Multiply the zoom; about the point, when given.
    Zoom(f64, Option<Point2<f64>>),
    /// Pan by a fraction of the view (x, y).
    Pan(f64, f64),
    /// Fit the bounds (or the slots) to the view.
    Fit,

    /// Open the find prompt (`/`): obstacles and IWPs by name.
    Find,
    /// Text typed into the find prompt.
    FindInput(char),
    FindBackspace,
    /// Clear the find prompt's text (Ctrl-u).
    FindClear,
    /// Select the match this many after the one selected (round the ends).
    FindStep(i32),
    /// Keep the match selected (Enter): the prompt closes, `n` / `N` step on.
    FindKeep,
    /// Close the prompt and go back to what was selected before (Esc).
    FindCancel,

    /// A new obstacle at the point, or at the view's centre.
    AddObstacle(Option<Point2<f64>>),
    /// A place the route must take (`[[route.via]]`): a gate by the
    /// selected obstacle, else a point at the view's centre.
    AddVia,
    ToggleAddTool,
    Duplicate,
    Delete,
    AddSlot,
    CyclePreset,
    /// Cycle the selected IWP's shape: auto → alignment → rotation → shrink.
    CycleShape,
    /// Enable/disable the selected IWP.
    ToggleWaypoint,
    /// Inspect (eq. 8) the selected obstacle, or stop inspecting it.
    ToggleInspect,
    /// From a footprint to its first vertex, or from a vertex back to its
    /// footprint (vertices are then moved, added and deleted).
    ToggleVertices,

    FieldUp,
    FieldDown,
    /// Start typing into the field under the cursor (optionally with a first character).
    EditStart(Option<char>),
    EditInput(char),
    EditBackspace,
    /// Clear the line being typed (Ctrl-u), as in a shell.
    EditClear,
    EditCommit,
    EditCancel,

    Undo,
    Redo,

    /// Run a pipeline with the mission's seed.
    Run(Kind),
    /// Live planning on or off: the plan follows every edit.
    ToggleLive,
    /// Run a pipeline with its agents in processes of their own, over Zenoh
    /// (the key table binds it for the fleet; lockstep: the same result as
    /// `Run` of the same pipeline).
    RunDistributed(Kind),
    /// Fly the shown plan in the mission's `[flight]` air (`skyform fly`).
    FlightCheck,
    /// Move the fleet replay by this many seconds (and pause it).
    Scrub(f64),
    /// Play or pause the fleet replay.
    TogglePlay,
    /// Re-run the last pipeline with a seed not used yet.
    RunNewSeed,
    /// Cancel the selected (or latest) running job.
    Cancel,
    JobUp,
    JobDown,
    /// Show the selected job's result on the map.
    ShowJob,
    ToggleRecording,
    CycleViewer,

    Save,
    SaveAs,
    Open,
    /// Yes to the prompt on screen.
    Confirm,
    /// Text typed into a prompt (save-as file name).
    PromptInput(char),
    PromptBackspace,
    /// Move in the open-file list.
    PickerMove(i32),

    /// A mouse drag of an item begins at a point of its pane.
    DragStart(Item, Point2<f64>),
    DragTo(Point2<f64>),
    DragEnd,

    /// Ask for a site survey (GeoJSON, KML, KMZ) to bring its obstacles in.
    Import,
    /// Export the shown job's result, one file per vehicle and format,
    /// beside the mission (re-verified as flown; refused if it breaks a constraint).
    Export,
}

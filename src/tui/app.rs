//! The TUI's state and its one mutator, [`App::update`].
//!
//! Nothing here draws or reads the terminal: the view (`view/`) is a pure
//! function of this state, and input (`input.rs`) only produces actions, so
//! the whole app can be driven and checked in tests without a terminal.
//!
//! Over 700 lines because `App` still holds most of the designer's state
//! (document, inspector, jobs, overlays) with one `update`; the camera
//! (`camera.rs`) and the replay (`replay.rs`) are components that own
//! theirs. Splitting out the rest the same way is the open part of issue 13.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, Sender, unbounded};
use nalgebra::{Point2, Vector3};

use super::action::Action;
pub use super::action::{Focus, Pane};
use super::camera::Camera;
use super::document::Document;
use super::fields::{self, Field, Item};
use super::jobs::{self, Job, JobId, JobMsg, Kind, RecordSettings, Viewer};
use super::recovery::{self, Origin, Recovery};
use super::replay::Replay;
use crate::geometry::farthest_offset;
use crate::mission::{self, Mission, Preset, Severity};
use crate::pipeline::Level;
use crate::planner::iwp::{self, min_pair_distance};
use crate::planner::{Iwp, find_iwps};

/// A line of text being typed into an inspector field.
#[derive(Debug, Clone, PartialEq)]
pub struct Editing {
    pub buffer: String,
    /// Why the text cannot be used, or the validation message it would cause
    /// (updated on every key).
    pub problem: Option<(Severity, String)>,
}

/// A file the open dialog offers.
#[derive(Debug, Clone, PartialEq)]
pub enum Entry {
    File(PathBuf),
    Builtin(&'static str),
}

impl Entry {
    pub fn label(&self) -> String {
        match self {
            Entry::File(p) => p.display().to_string(),
            Entry::Builtin(name) => format!("(built-in) {name}"),
        }
    }
}

/// What to do once a save went through (nothing happens if it did not).
#[derive(Debug, Clone, PartialEq)]
pub enum AfterSave {
    Stay,
    Quit,
    /// "Save first" in the open dialog's unsaved-changes prompt.
    Open(Entry),
}

/// A window on top of the screen that takes the keys.
#[derive(Debug, Clone, PartialEq)]
pub enum Overlay {
    Help,
    /// Unsaved changes: save, discard or stay.
    Quit,
    SaveAs {
        input: String,
        then: AfterSave,
    },
    /// The mission has errors: save anyway?
    SaveInvalid {
        path: Option<PathBuf>,
        errors: Vec<String>,
        then: AfterSave,
    },
    /// The open dialog: the missions found, the text typed (a filter, or
    /// a path to open that is not listed), what it leaves (`matches`) and
    /// the cursor in those.
    Open {
        entries: Vec<Entry>,
        input: String,
        matches: Vec<Entry>,
        cursor: usize,
    },
    /// Unsaved changes would be lost by opening `entry`: save first,
    /// discard them, or stay.
    Discard(Entry),
    /// "Save as" onto a file that exists: replace it?
    Overwrite {
        path: PathBuf,
        then: AfterSave,
    },
    /// An earlier session left unsaved changes: restore them?
    Recover(Box<recovery::Copy>),
}

/// The status line's message.
#[derive(Debug, Clone, PartialEq)]
pub struct Status {
    pub text: String,
    pub error: bool,
}

/// A drag in progress: the item and where it was grabbed relative to its position.
#[derive(Debug, Clone, PartialEq)]
struct Drag {
    item: Item,
    grab: nalgebra::Vector2<f64>,
}

/// The whole TUI state.
pub struct App {
    pub doc: Document,
    /// The IWPs of the current mission (eq. 9), refreshed on every change;
    /// empty while the mission has errors.
    pub iwps: Vec<Iwp>,
    pub selected: Item,
    /// Inspector cursor.
    pub field: usize,
    pub editing: Option<Editing>,
    pub focus: Focus,
    pub pane: Pane,
    pub side_view: bool,
    /// Zoom, pan and nudge step (its own component).
    camera: Camera,
    /// Clicking an empty spot of the map places an obstacle.
    pub add_tool: bool,
    pub preset: Preset,
    pub jobs: Vec<Job>,
    pub job_cursor: usize,
    /// The job whose result the map shows.
    pub shown_job: Option<JobId>,
    pub overlay: Option<Overlay>,
    pub status: Option<Status>,
    /// Record runs to an `.rrd` beside the mission.
    pub record_rrd: bool,
    pub viewer: Viewer,
    /// The fleet replay (its own component).
    replay: Replay,
    pub should_quit: bool,
    /// Where relative paths (save as, open) start.
    pub cwd: PathBuf,
    /// First line of the help overlay shown (it scrolls on small screens).
    pub help_scroll: u16,
    /// The recovery copy of unsaved edits; `None` unless enabled.
    recovery: Option<Recovery>,
    drag: Option<Drag>,
    job_tx: Sender<JobMsg>,
    job_rx: Receiver<JobMsg>,
}

impl App {
    pub fn new(doc: Document, cwd: PathBuf) -> Self {
        let (job_tx, job_rx) = unbounded();
        let mut app = App {
            doc,
            iwps: Vec::new(),
            selected: Item::Mission,
            field: 0,
            editing: None,
            focus: Focus::Map,
            pane: Pane::Map,
            side_view: false,
            camera: Camera::default(),
            add_tool: false,
            preset: Preset::Triangle,
            jobs: Vec::new(),
            job_cursor: 0,
            shown_job: None,
            overlay: None,
            status: None,
            record_rrd: false,
            viewer: Viewer::Off,
            replay: Replay::default(),
            should_quit: false,
            cwd,
            drag: None,
            recovery: None,
            help_scroll: 0,
            job_tx,
            job_rx,
        };
        app.refresh();
        app
    }

    pub fn mission(&self) -> &Mission {
        self.doc.mission()
    }

    /// The channel the main loop waits on, next to input.
    pub fn job_messages(&self) -> &Receiver<JobMsg> {
        &self.job_rx
    }

    pub fn step_size(&self) -> f64 {
        self.camera.step_size()
    }

    /// How the map and the formation editor are looked at.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Whether the fleet replay is playing.
    pub fn is_playing(&self) -> bool {
        self.replay.is_playing()
    }

    pub fn any_running(&self) -> bool {
        self.jobs.iter().any(Job::is_running)
    }

    /// The x-y box the map fits at zoom 1: the bounds, grown to hold a shown
    /// FLATLO flight (kilometres, wherever the mission's bounds are). Pan and
    /// zoom start from the same box the view draws.
    pub fn map_extent(&self) -> ([f64; 2], [f64; 2]) {
        let b = &self.mission().bounds;
        let (mut x, mut y) = (b.x, b.y);
        if let Some(o) = self
            .shown()
            .and_then(|j| j.outcome.as_ref())
            .and_then(|o| o.flatlo())
        {
            for a in &o.aircraft {
                for p in a
                    .reference
                    .iter()
                    .map(|s| s.position)
                    .chain(a.flown.iter().map(|s| s.position))
                {
                    x = [x[0].min(p.x), x[1].max(p.x)];
                    y = [y[0].min(p.y), y[1].max(p.y)];
                }
            }
        }
        (x, y)
    }

    /// Where the map looks: the panned centre, or the middle of the extent.
    pub fn map_center(&self) -> Point2<f64> {
        self.camera.map_center(self.map_extent())
    }

    /// Duration of the shown fleet result, if one is shown (the replay's range).
    pub fn replay_end(&self) -> Option<f64> {
        let o = self.shown()?.outcome.as_ref()?.fleet()?;
        Some(o.duration)
    }

    /// The fleet replay instant on the map: the replay cursor, or the end.
    pub fn replay_time(&self) -> Option<f64> {
        self.replay_end().map(|end| self.replay.time(end))
    }

    /// The loop needs to wake up by itself (running jobs, a playing replay).
    pub fn wants_tick(&self) -> bool {
        self.any_running() || self.replay.is_playing() || self.recovery_pending()
    }

    /// Keeps a recovery copy of unsaved edits (`recovery.rs`) for the
    /// document from `origin`; offers an earlier session's copy. The
    /// designer turns this on; tests and headless uses of `App` leave it off.
    pub fn enable_recovery(&mut self, origin: Origin) {
        self.use_recovery(Recovery::new(&origin));
    }

    /// `enable_recovery` with the copy kept where `recovery` says (tests).
    pub fn use_recovery(&mut self, recovery: Recovery) {
        let existing = recovery.existing();
        self.recovery = Some(recovery);
        match existing {
            Some(copy) if &copy.mission != self.mission() => {
                self.overlay = Some(Overlay::Recover(Box::new(copy)));
            }
            Some(_) => {
                if let Some(r) = &mut self.recovery {
                    r.discard();
                }
            }
            None => {}
        }
    }

    /// Where this document's recovery copy is kept, when one is.
    pub fn recovery_path(&self) -> Option<&Path> {
        self.recovery.as_ref().and_then(Recovery::path)
    }

    fn recovery_pending(&self) -> bool {
        self.recovery
            .as_ref()
            .is_some_and(|r| r.pending(self.doc.mission(), self.doc.is_modified()))
    }

    /// Brings the recovery copy in line with the document (after every
    /// action and tick; `force` on the way out). Left alone while the
    /// restore question is open, so an earlier copy is never overwritten
    /// before the user answers.
    pub fn keep_recovery(&mut self, now: Instant, force: bool) {
        if matches!(self.overlay, Some(Overlay::Recover(_))) {
            return;
        }
        let Some(r) = &mut self.recovery else {
            return;
        };
        let had_failed = r.failed.is_some();
        r.keep(
            self.doc.mission(),
            self.doc.is_modified(),
            self.doc.changes(),
            now,
            force,
        );
        if let (false, Some(e)) = (had_failed, r.failed.clone()) {
            self.set_error(e);
        }
    }

    /// Time passed: a playing replay advances at real speed; a held-back
    /// recovery write goes out.
    pub fn tick(&mut self, elapsed: Duration) {
        self.keep_recovery(Instant::now(), false);
        if let Some(end) = self.replay_end() {
            self.replay.advance(elapsed, end);
        }
    }

    /// The job whose result is on the map.
    pub fn shown(&self) -> Option<&Job> {
        let id = self.shown_job?;
        self.jobs.iter().find(|j| j.id == id)
    }

    /// A result is stale when the mission changed after its run started.
    pub fn is_stale(&self, job: &Job) -> bool {
        &job.mission != self.mission()
    }

    /// The inspector's fields for the selection.
    pub fn fields(&self) -> Vec<Field> {
        fields::fields(&self.selected, self.mission())
    }

    fn set_status(&mut self, text: impl Into<String>) {
        self.status = Some(Status {
            text: text.into(),
            error: false,
        });
    }

    fn set_error(&mut self, text: impl Into<String>) {
        self.status = Some(Status {
            text: text.into(),
            error: true,
        });
    }

    /// After any change to the mission: keep the selection valid, recompute IWPs.
    fn refresh(&mut self) {
        let m = self.doc.mission();
        self.iwps = iwps_despite_choices(m, self.doc.diagnostics());
        if !self.selected.exists(m) {
            self.selected = match self.selected {
                Item::Obstacle(_) if !m.obstacles.is_empty() => {
                    Item::Obstacle(m.obstacles.len() - 1)
                }
                Item::Slot(_) | Item::Waypoint(_) => Item::Formation,
                _ => Item::Bounds,
            };
        }
        let n = fields::fields(&self.selected, m).len();
        self.field = self.field.min(n.saturating_sub(1));
    }

    fn edit(&mut self, change: impl FnOnce(&mut Mission)) {
        self.doc.edit(change);
        // An error message is about what was; a change moves on from it.
        if self.status.as_ref().is_some_and(|s| s.error) {
            self.status = None;
        }
        self.refresh();
    }

    /// Changes state for one action. Never panics on user input.
    pub fn update(&mut self, action: Action) {
        use Action::*;
        match action {
            Quit => self.quit(),
            ScrollHelp(by) => {
                self.help_scroll =
                    (i64::from(self.help_scroll) + i64::from(by)).clamp(0, 500) as u16;
            }
            ToggleHelp => {
                self.help_scroll = 0;
                self.overlay = match self.overlay {
                    Some(Overlay::Help) => None,
                    _ => Some(Overlay::Help),
                }
            }
            Dismiss if matches!(self.overlay, Some(Overlay::Recover(_))) => {
                self.overlay = None;
                if let Some(r) = &mut self.recovery {
                    r.discard();
                }
                self.set_status("the recovery copy was discarded");
            }
            Dismiss => {
                if self.editing.is_some() {
                    self.editing = None;
                } else if self.overlay.is_some() {
                    self.overlay = None;
                } else if self.add_tool {
                    self.add_tool = false;
                }
            }
            FocusNext | FocusPrevious => {
                self.editing = None;
                let order = [Focus::Map, Focus::Inspector, Focus::Jobs];
                let i = order.iter().position(|f| *f == self.focus).unwrap_or(0);
                let d = if action == FocusNext {
                    1
                } else {
                    order.len() - 1
                };
                self.focus = order[(i + d) % order.len()];
            }
            FocusOn(focus) => {
                if focus != self.focus {
                    self.editing = None;
                }
                self.focus = focus;
            }
            ShowMap => {
                self.pane = Pane::Map;
                if !fields::map_items(self.mission()).contains(&self.selected) {
                    self.select(Item::Bounds);
                }
            }
            ShowFormation => {
                self.pane = Pane::Formation;
                self.side_view = false;
                if !fields::formation_items(self.mission(), &self.iwps).contains(&self.selected) {
                    self.select(Item::Formation);
                }
            }
            ToggleSideView => {
                if self.pane == Pane::Map {
                    self.side_view = !self.side_view;
                }
            }
            SelectNext | SelectPrevious => {
                let items = match self.pane {
                    Pane::Map => fields::map_items(self.mission()),
                    Pane::Formation => fields::formation_items(self.mission(), &self.iwps),
                };
                if !items.is_empty() {
                    let i = items.iter().position(|it| *it == self.selected);
                    let n = items.len();
                    let next = match (i, action == SelectNext) {
                        (Some(i), true) => (i + 1) % n,
                        (Some(i), false) => (i + n - 1) % n,
                        (None, _) => 0,
                    };
                    self.select(items[next].clone());
                }
            }
            Select(item) => self.select(item),
            Nudge(dx, dy) => self.nudge(dx, dy),
            ChangeStep(d) => {
                self.camera.change_step(d);
                self.set_status(format!(
                    "nudge step {} m",
                    fields::fmt_num(self.step_size())
                ));
            }
            Zoom(factor, at) => self.zoom_by(factor, at),
            Pan(fx, fy) => {
                let extent = self.map_extent();
                self.camera.pan(fx, fy, extent);
            }
            Fit => match self.pane {
                Pane::Map => self.camera.fit_map(),
                Pane::Formation => self.camera.fit_formation(),
            },
            AddObstacle(at) => {
                let p = at
                    .or(self.camera.panned_center())
                    .unwrap_or(self.mission().bounds.center_xy());
                let obstacle = fields::new_obstacle(self.mission(), p);
                let name = obstacle.name.clone();
                self.edit(|m| m.obstacles.push(obstacle));
                let i = self.mission().obstacles.len() - 1;
                self.pane = Pane::Map;
                self.select(Item::Obstacle(i));
                self.set_status(format!("added '{name}' at ({:.1}, {:.1})", p.x, p.y));
            }
            ToggleAddTool => {
                self.add_tool = !self.add_tool;
                self.set_status(if self.add_tool {
                    "add tool: click an empty spot of the map to place an obstacle (Esc to stop)"
                } else {
                    "add tool off"
                });
            }
            Duplicate if matches!(self.selected, Item::Fleet | Item::FleetTarget(_)) => {
                // A new target 10 s after the last, 1 m east of it.
                let last = self.mission().fleet.targets.last().cloned();
                let next = match last {
                    Some(t) => crate::mission::FleetTarget {
                        time: t.time + 10.0,
                        position: t.position + nalgebra::Vector2::new(1.0, 0.0),
                    },
                    None => crate::mission::FleetTarget {
                        time: 0.0,
                        position: crate::fleet::default_target(self.mission()),
                    },
                };
                self.edit(|m| m.fleet.targets.push(next));
                self.select(Item::FleetTarget(self.mission().fleet.targets.len() - 1));
            }
            ToggleInspect => {
                if let Item::Obstacle(i) = self.selected
                    && let Some(o) = self.mission().obstacles.get(i)
                {
                    let inspect = !o.inspect;
                    let name = o.name.clone();
                    self.edit(|m| m.obstacles[i].inspect = inspect);
                    self.set_status(if inspect {
                        format!("inspecting '{name}': the plan flies a pass along it (eq. 8)")
                    } else {
                        format!("'{name}' is no longer inspected")
                    });
                } else {
                    self.set_status("select an obstacle (n/p or click) to inspect it".to_owned());
                }
            }
            Duplicate => {
                if let Item::Obstacle(i) = self.selected
                    && let Some(o) = self.mission().obstacles.get(i)
                {
                    let copy = fields::duplicate_obstacle(self.mission(), o);
                    self.edit(|m| m.obstacles.push(copy));
                    self.select(Item::Obstacle(self.mission().obstacles.len() - 1));
                }
            }
            Delete => self.delete(),
            AddSlot => {
                let slots = &self.mission().formation.slots;
                let back = slots.iter().map(|s| s.x).fold(0.0, f64::min);
                let spacing = self.preset_spacing();
                self.edit(|m| {
                    m.formation
                        .slots
                        .push(Vector3::new(back - spacing, 0.0, 0.0))
                });
                self.select(Item::Slot(self.mission().formation.slots.len() - 1));
            }
            CyclePreset => {
                self.preset = self.preset.next();
                let n = self.mission().formation.slots.len().max(1);
                let spacing = self.preset_spacing();
                let slots = self.preset.slots(n, spacing);
                self.edit(|m| m.formation.slots = slots);
                self.set_status(format!(
                    "formation: {} of {n}, {} m apart",
                    self.preset.name(),
                    fields::fmt_num(spacing)
                ));
            }
            CycleShape => {
                if let Item::Waypoint(_) = &self.selected {
                    let item = self.selected.clone();
                    self.edit(|m| {
                        if let Ok(choice) = fields::waypoint_choice(m, &item) {
                            choice.shape = fields::next_shape(choice.shape);
                        }
                    });
                } else {
                    // Say what `s` needs rather than do nothing.
                    let iwps = self.iwps.len();
                    self.set_error(if iwps == 0 {
                        "s changes an IWP's shape: this mission has no IWP".to_owned()
                    } else {
                        format!(
                            "s changes an IWP's shape: select one of the {iwps} IWP row(s) \
                             first (2 formation editor, then n)"
                        )
                    });
                }
            }
            ToggleWaypoint => {
                if let Item::Waypoint(_) = &self.selected {
                    let item = self.selected.clone();
                    self.edit(|m| {
                        if let Ok(choice) = fields::waypoint_choice(m, &item) {
                            choice.enabled = !choice.enabled;
                        }
                    });
                }
            }
            FieldUp => {
                self.editing = None;
                self.field = self.field.saturating_sub(1);
            }
            FieldDown => {
                self.editing = None;
                let n = self.fields().len();
                self.field = (self.field + 1).min(n.saturating_sub(1));
            }
            EditStart(first) => {
                let fields = self.fields();
                if let Some(f) = fields.get(self.field) {
                    let buffer = match first {
                        Some(c) => c.to_string(),
                        None => f.value.clone(),
                    };
                    self.focus = Focus::Inspector;
                    self.editing = Some(Editing {
                        buffer,
                        problem: None,
                    });
                    self.check_editing();
                }
            }
            EditInput(c) => {
                if let Some(e) = &mut self.editing {
                    e.buffer.push(c);
                    self.check_editing();
                }
            }
            EditBackspace => {
                if let Some(e) = &mut self.editing {
                    e.buffer.pop();
                    self.check_editing();
                }
            }
            EditCommit => self.commit_edit(),
            EditCancel => self.editing = None,
            Undo => {
                self.editing = None;
                self.drag = None;
                if self.doc.undo() {
                    self.refresh();
                    self.set_status("undone");
                } else {
                    self.set_status("nothing to undo");
                }
            }
            Redo => {
                self.editing = None;
                self.drag = None;
                if self.doc.redo() {
                    self.refresh();
                    self.set_status("redone");
                } else {
                    self.set_status("nothing to redo");
                }
            }
            Run => self.run(Kind::ThetaPso, self.mission().seed),
            RunFlatlo => self.run(Kind::Flatlo, self.mission().seed),
            RunFleet => self.run(Kind::Fleet, self.mission().seed),
            Scrub(seconds) => {
                if let Some(end) = self.replay_end() {
                    self.replay.scrub(seconds, end);
                }
            }
            TogglePlay => {
                if let Some(end) = self.replay_end() {
                    self.replay.toggle(end);
                }
            }
            RunNewSeed => {
                let seed = self
                    .jobs
                    .iter()
                    .map(|j| j.seed)
                    .max()
                    .map_or(self.mission().seed.wrapping_add(1), |s| s.wrapping_add(1));
                let pipeline = self.jobs.last().map_or(Kind::ThetaPso, |j| j.pipeline);
                self.run(pipeline, seed);
            }
            Cancel => {
                let target = self
                    .jobs
                    .get(self.job_cursor)
                    .filter(|j| j.is_running())
                    .or_else(|| self.jobs.iter().rev().find(|j| j.is_running()));
                match target {
                    Some(job) => {
                        job.cancel.cancel();
                        let id = job.id;
                        self.set_status(format!("cancelling job {id}…"));
                    }
                    None => self.set_status("no job is running"),
                }
            }
            JobUp => self.job_cursor = self.job_cursor.saturating_sub(1),
            JobDown => {
                self.job_cursor = (self.job_cursor + 1).min(self.jobs.len().saturating_sub(1))
            }
            ShowJob => {
                if let Some(job) = self.jobs.get(self.job_cursor) {
                    self.shown_job = Some(job.id);
                    self.pane = Pane::Map;
                }
            }
            ToggleRecording => {
                self.record_rrd = !self.record_rrd;
                self.set_status(if self.record_rrd {
                    "runs are recorded to an .rrd beside the mission"
                } else {
                    "runs are not recorded"
                });
            }
            CycleViewer => {
                self.viewer = self.viewer.next();
                self.set_status(match self.viewer {
                    Viewer::Off => "no Rerun viewer".to_owned(),
                    Viewer::Connect => {
                        "runs stream to a running Rerun viewer (rerun --port 9876)".to_owned()
                    }
                    Viewer::Spawn => "runs start a Rerun viewer (`rerun` on PATH)".to_owned(),
                });
                // Say now when the viewer cannot be reached, not at the run.
                #[cfg(feature = "rerun")]
                if self.viewer != Viewer::Off
                    && let Some(problem) =
                        crate::record::viewer_problem(self.viewer == Viewer::Spawn)
                {
                    self.set_error(format!("warning: {problem}"));
                }
            }
            Save => match &self.overlay {
                Some(Overlay::Quit) => self.save(None, AfterSave::Quit, false),
                Some(Overlay::Discard(entry)) => {
                    let then = AfterSave::Open(entry.clone());
                    self.save(None, then, false);
                }
                _ => self.save(None, AfterSave::Stay, false),
            },
            SaveAs => {
                // Pre-filled relative to the working directory when it can be.
                let input = self
                    .doc
                    .path()
                    .map(|p| p.strip_prefix(&self.cwd).unwrap_or(p).display().to_string())
                    .unwrap_or_else(|| format!("{}.toml", slug(&self.mission().name)));
                self.overlay = Some(Overlay::SaveAs {
                    input,
                    then: AfterSave::Stay,
                });
            }
            Open => {
                let entries = open_entries(&self.cwd);
                self.overlay = Some(Overlay::Open {
                    matches: entries.clone(),
                    entries,
                    input: String::new(),
                    cursor: 0,
                });
            }
            Confirm => self.confirm(),
            PromptInput(c) => self.edit_prompt(|input| input.push(c)),
            PromptClear => self.edit_prompt(String::clear),
            PromptBackspace => self.edit_prompt(|input| {
                input.pop();
            }),
            PickerMove(d) => {
                if let Some(Overlay::Open {
                    matches, cursor, ..
                }) = &mut self.overlay
                {
                    let n = matches.len() as i32;
                    if n > 0 {
                        *cursor = (*cursor as i32 + d).clamp(0, n - 1) as usize;
                    }
                }
            }
            DragStart(item, at) => {
                // A drag whose release was never seen ends here.
                if self.drag.take().is_some() {
                    self.doc.end_gesture();
                }
                self.select(item.clone());
                if let Some(position) = self.position_of(&item) {
                    self.doc.begin_gesture();
                    self.drag = Some(Drag {
                        item,
                        grab: position - at,
                    });
                }
            }
            DragTo(at) => {
                if let Some(drag) = self.drag.clone() {
                    // Dragged positions snap to the nudge step, as the keys move.
                    let step = self.step_size();
                    let snap = |v: f64| (v / step).round() * step;
                    let p = at + drag.grab;
                    let p = Point2::new(snap(p.x), snap(p.y));
                    self.doc.gesture_edit(|m| set_position(m, &drag.item, p));
                }
            }
            DragEnd => {
                if self.drag.take().is_some() {
                    self.doc.end_gesture();
                    self.refresh();
                }
            }
            Export => self.export_shown(),
        }
    }

    /// Exports the shown job's result beside the mission; the status line
    /// says where, or why not.
    fn export_shown(&mut self) {
        let Some(job) = self.shown() else {
            self.set_error("no result on the map to export: run a pipeline, or Enter on a job");
            return;
        };
        let stem = self
            .doc
            .path()
            .and_then(Path::file_stem)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| slug(&job.mission.name));
        let dir = super::export::folder(self.doc.path(), &self.cwd, &stem);
        match super::export::export_job(job, &dir, &stem) {
            Ok(text) => self.set_status(text),
            Err(text) => self.set_error(text),
        }
    }

    fn select(&mut self, item: Item) {
        if item != self.selected {
            self.editing = None;
            self.field = 0;
        }
        self.selected = item;
    }

    /// Changes the text of the prompt on screen (save as, open); the open
    /// dialog filters its list by it.
    fn edit_prompt(&mut self, change: impl FnOnce(&mut String)) {
        match &mut self.overlay {
            Some(Overlay::SaveAs { input, .. }) => change(input),
            Some(Overlay::Open {
                entries,
                input,
                matches,
                cursor,
            }) => {
                change(input);
                *matches = open_matches(entries, input, &self.cwd);
                *cursor = 0;
            }
            _ => {}
        }
    }

    fn quit(&mut self) {
        if self.doc.is_modified() {
            self.overlay = Some(Overlay::Quit);
        } else {
            self.shutdown();
        }
    }

    /// Quits without asking (a signal: the terminal is closing or the
    /// process is told to stop). Unsaved edits stay in the recovery copy.
    pub fn quit_now(&mut self) {
        self.keep_recovery(Instant::now(), true);
        self.shutdown();
    }

    /// Cancels running jobs (they return their best at once) and stops.
    fn shutdown(&mut self) {
        for job in self.jobs.iter().filter(|j| j.is_running()) {
            job.cancel.cancel();
        }
        self.should_quit = true;
    }

    /// The preset the slots are now (after any undo), if they are one.
    pub fn current_preset(&self) -> Option<Preset> {
        let slots = &self.mission().formation.slots;
        let spacing = self.preset_spacing();
        Preset::ALL.into_iter().find(|p| {
            let made = p.slots(slots.len().max(1), spacing);
            made.len() == slots.len() && made.iter().zip(slots).all(|(a, b)| (a - b).norm() < 1e-9)
        })
    }

    fn preset_spacing(&self) -> f64 {
        let f = &self.mission().formation;
        let d = min_pair_distance(&f.slots);
        let floor = 2.0 * f.uav_radius + 1.0;
        if d.is_finite() {
            d.max(floor)
        } else {
            floor.max(2.0)
        }
    }

    fn zoom_by(&mut self, factor: f64, at: Option<Point2<f64>>) {
        match self.pane {
            Pane::Map => {
                let extent = self.map_extent();
                self.camera.zoom_map(factor, at, extent);
            }
            Pane::Formation => self.camera.zoom_formation(factor),
        }
    }

    fn nudge(&mut self, dx: f64, dy: f64) {
        let s = self.step_size();
        let item = self.selected.clone();
        match &item {
            Item::Obstacle(_) | Item::Start | Item::Goal | Item::FleetTarget(_) => {
                if let Some(p) = self.position_of(&item) {
                    let to = p + nalgebra::Vector2::new(dx * s, dy * s);
                    self.edit(|m| set_position(m, &item, to));
                }
            }
            Item::Slot(i) => {
                let i = *i;
                // Formation frame on screen: forward is up, left is left.
                self.edit(|m| {
                    if let Some(slot) = m.formation.slots.get_mut(i) {
                        slot.x += dy * s;
                        slot.y -= dx * s;
                    }
                });
            }
            _ => self.set_status("select an obstacle, the start, the goal or a slot to move it"),
        }
    }

    /// Where a movable item is, in its pane's plane (map: x, y ENU; formation:
    /// forward, left).
    pub fn position_of(&self, item: &Item) -> Option<Point2<f64>> {
        let m = self.mission();
        match item {
            Item::Obstacle(i) => m.obstacles.get(*i).map(|o| o.center),
            Item::Start => Some(m.route.start.xy()),
            Item::Goal => Some(m.route.goal.xy()),
            Item::Slot(i) => m.formation.slots.get(*i).map(|s| Point2::new(s.x, s.y)),
            Item::FleetTarget(i) => m.fleet.targets.get(*i).map(|t| t.position),
            _ => None,
        }
    }

    fn delete(&mut self) {
        match self.selected.clone() {
            Item::Obstacle(i) => {
                let name = self.mission().obstacles.get(i).map(|o| o.name.clone());
                self.edit(|m| {
                    if i < m.obstacles.len() {
                        m.obstacles.remove(i);
                    }
                });
                if let Some(name) = name {
                    self.set_status(format!("deleted '{name}' (u to undo)"));
                }
            }
            Item::Slot(i) => {
                if self.mission().formation.slots.len() <= 1 {
                    self.set_error("a formation needs at least one slot");
                    return;
                }
                self.edit(|m| {
                    if i < m.formation.slots.len() {
                        m.formation.slots.remove(i);
                    }
                });
            }
            Item::FleetTarget(i) => {
                self.edit(|m| {
                    if i < m.fleet.targets.len() {
                        m.fleet.targets.remove(i);
                    }
                });
                self.set_status("fleet target deleted (u to undo)");
            }
            Item::Waypoint(between) => {
                self.edit(|m| {
                    m.reconfiguration
                        .waypoints
                        .retain(|w| !iwp::same_pair(&w.between, &between[0], &between[1]))
                });
                self.set_status("IWP back to the mission's default shape");
            }
            _ => self.set_status("only obstacles, slots and IWP choices can be deleted"),
        }
    }

    /// Re-checks the text being typed: parse it, apply it to a copy, validate.
    fn check_editing(&mut self) {
        let fields = self.fields();
        let Some(field) = fields.get(self.field) else {
            return;
        };
        let Some(editing) = &self.editing else {
            return;
        };
        let mut trial = self.mission().clone();
        let problem = match field.set(&mut trial, &self.selected, &editing.buffer) {
            Err(e) => Some((Severity::Error, e)),
            Ok(()) => crate::diagnose::diagnose(&trial)
                .into_iter()
                .filter(|d| concerns(&d.path.to_string(), &field.path))
                .min_by_key(|d| d.severity)
                .map(|d| (d.severity, d.message)),
        };
        if let Some(e) = &mut self.editing {
            e.problem = problem;
        }
    }

    fn commit_edit(&mut self) {
        let Some(editing) = self.editing.take() else {
            return;
        };
        let fields = self.fields();
        let Some(field) = fields.get(self.field) else {
            return;
        };
        // Enter applies and stays on the field: ↓ goes to the next one (a
        // move on Enter as well made the next ↓ skip a field).
        if editing.buffer.trim() == field.value {
            // Nothing typed: no change, no undo step (and no rounding).
            return;
        }
        let mut trial = self.mission().clone();
        match field.set(&mut trial, &self.selected, &editing.buffer) {
            Ok(()) => {
                self.edit(|m| *m = trial);
                self.set_status(format!("{} = {}", field.label, editing.buffer.trim()));
            }
            Err(e) => {
                // Keep the text so it can be corrected.
                self.set_error(format!("{}: {e}", field.label));
                self.editing = Some(Editing {
                    problem: Some((Severity::Error, e)),
                    ..editing
                });
            }
        }
    }

    fn run(&mut self, pipeline: Kind, seed: u64) {
        let errors = self.doc.error_lines();
        if let Some(first) = errors.first() {
            self.set_error(format!(
                "cannot run: {} error(s) in the mission; first: {first}",
                errors.len()
            ));
            return;
        }
        let id = self.jobs.last().map_or(1, |j| j.id + 1);
        let job = Job::new(id, pipeline, seed, self.mission().clone(), Instant::now());
        let record = RecordSettings {
            rrd: self
                .record_rrd
                .then(|| self.rrd_path(pipeline.slug(), seed)),
            viewer: self.viewer,
        };
        jobs::spawn_pipeline(
            id,
            pipeline,
            job.mission.clone(),
            seed,
            job.cancel.clone(),
            record,
            self.job_tx.clone(),
        );
        self.jobs.push(job);
        self.job_cursor = self.jobs.len() - 1;
        self.set_status(format!(
            "job {id}: {} started with seed {seed} (x cancels)",
            pipeline.name()
        ));
    }

    /// `<mission file stem>-<pipeline>-seed<N>.rrd` beside the mission file.
    pub fn rrd_path(&self, pipeline: &str, seed: u64) -> PathBuf {
        let (dir, stem) = match self.doc.path() {
            Some(p) => (
                p.parent().map(Path::to_path_buf).unwrap_or_default(),
                p.file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_else(|| slug(&self.mission().name)),
            ),
            None => (self.cwd.clone(), slug(&self.mission().name)),
        };
        dir.join(format!("{stem}-{pipeline}-seed{seed}.rrd"))
    }

    /// Applies a worker's message (`now` stamps job ends).
    pub fn on_job_msg(&mut self, msg: JobMsg, now: Instant) {
        let id = msg.job();
        let note = match &msg {
            JobMsg::Log(_, Level::Warn, text) => Some((true, format!("job {id}: {text}"))),
            JobMsg::Recorded { path, bytes, .. } => Some((
                false,
                format!(
                    "job {id}: recorded {} ({:.1} MB)",
                    path.display(),
                    *bytes as f64 / 1e6
                ),
            )),
            JobMsg::Done(_, Err(e)) => Some((true, format!("job {id} failed: {e}"))),
            _ => None,
        };
        let done = matches!(msg, JobMsg::Done(_, Ok(_)));
        if let Some(job) = self.jobs.iter_mut().find(|j| j.id == id) {
            job.apply(msg, now);
            if done {
                let verb = if job.state == jobs::JobState::Cancelled {
                    "cancelled"
                } else {
                    "done"
                };
                let text = match &job.outcome {
                    Some(o) => format!("job {id} {verb}: {}", o.headline()),
                    None => format!("job {id} {verb}"),
                };
                self.shown_job = Some(id);
                self.replay.reset();
                self.set_status(text);
            }
        }
        if let Some((error, text)) = note {
            self.status = Some(Status { text, error });
        }
    }

    /// Applies every message already waiting; returns whether there was any.
    pub fn drain_job_messages(&mut self) -> bool {
        let mut any = false;
        while let Ok(msg) = self.job_rx.try_recv() {
            self.on_job_msg(msg, Instant::now());
            any = true;
        }
        any
    }

    /// Blocks until no job runs (tests, headless use). False on timeout.
    pub fn wait_for_jobs(&mut self, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        while self.any_running() {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.job_rx.recv_timeout(left) {
                Ok(msg) => self.on_job_msg(msg, Instant::now()),
                Err(_) => return false,
            }
        }
        self.drain_job_messages();
        true
    }

    fn save(&mut self, path: Option<PathBuf>, then: AfterSave, confirmed: bool) {
        let target = path.or_else(|| self.doc.path().map(Path::to_path_buf));
        let Some(target) = target else {
            self.overlay = Some(Overlay::SaveAs {
                input: format!("{}.toml", slug(&self.mission().name)),
                then,
            });
            return;
        };
        let errors = self.doc.error_lines();
        if !errors.is_empty() && !confirmed {
            self.overlay = Some(Overlay::SaveInvalid {
                path: Some(target),
                errors,
                then,
            });
            return;
        }
        let target = if target.is_relative() {
            self.cwd.join(target)
        } else {
            target
        };
        // "Save as" into a folder that does not exist yet creates it.
        if let Some(dir) = target.parent()
            && !dir.as_os_str().is_empty()
            && !dir.exists()
            && let Err(e) = std::fs::create_dir_all(dir)
        {
            self.overlay = None;
            self.set_error(format!("not saved: cannot create {}: {e}", dir.display()));
            return;
        }
        let before = self.doc.path().map(Path::to_path_buf);
        match self.doc.save(Some(target)) {
            Ok(p) => {
                // Saved as another file: later edits are recovered for it.
                if before.as_ref() != Some(&p)
                    && let Some(mut old) = self.recovery.take()
                {
                    old.discard();
                    let mut fresh = old.moved_to(&Origin::File(p.clone()));
                    fresh.discard();
                    self.recovery = Some(fresh);
                }
                self.overlay = None;
                let saved = format!("saved {}", p.display());
                self.set_status(saved.clone());
                match then {
                    AfterSave::Stay => {}
                    AfterSave::Quit => self.shutdown(),
                    AfterSave::Open(entry) => {
                        self.open(entry);
                        if let Some(s) = self.status.as_mut().filter(|s| !s.error) {
                            s.text = format!("{saved} · {}", s.text);
                        }
                    }
                }
            }
            Err(e) => {
                self.overlay = None;
                self.set_error(format!("not saved: {e}"));
            }
        }
    }

    fn confirm(&mut self) {
        match self.overlay.clone() {
            Some(Overlay::Quit) => {
                // Quit without saving: the user chose to drop the changes, so
                // no copy may be written on the way out either.
                self.overlay = None;
                if let Some(mut r) = self.recovery.take() {
                    r.discard();
                }
                self.shutdown();
            }
            Some(Overlay::SaveAs { input, then }) => {
                let input = input.trim();
                if input.is_empty() {
                    self.set_error("type a file name");
                    return;
                }
                let path = self.cwd.join(input);
                let current = self.doc.path().map(|p| self.cwd.join(p));
                if path.exists() && current.as_ref() != Some(&path) {
                    self.overlay = Some(Overlay::Overwrite { path, then });
                    return;
                }
                self.save(Some(path), then, false);
            }
            Some(Overlay::Overwrite { path, then }) => self.save(Some(path), then, false),
            Some(Overlay::Recover(copy)) => {
                self.overlay = None;
                let changes = copy.changes;
                self.doc.edit(|m| *m = copy.mission);
                self.refresh();
                self.set_status(format!(
                    "restored {changes} unsaved change(s); Ctrl-s saves them, u undoes the restore"
                ));
            }
            Some(Overlay::SaveInvalid { path, then, .. }) => self.save(path, then, true),
            Some(Overlay::Open {
                matches, cursor, ..
            }) => {
                let Some(entry) = matches.get(cursor).cloned() else {
                    self.set_error("nothing to open: type a path or pick a listed mission");
                    return;
                };
                // A file that cannot be opened is refused here, before the
                // unsaved-changes question; the dialog stays to fix the path.
                match load(&entry) {
                    Err(e) => self.set_error(e),
                    Ok(_) if self.doc.is_modified() => {
                        self.overlay = Some(Overlay::Discard(entry));
                    }
                    Ok(loaded) => self.install(entry, loaded),
                }
            }
            Some(Overlay::Discard(entry)) => self.open(entry),
            Some(Overlay::Help) | None => {}
        }
    }

    /// Replaces the document with another mission. A file that cannot be
    /// read as a mission at all is refused (the status says why, naming
    /// it, and the document stays); one with validation errors opens (the
    /// inspector shows them).
    pub fn open(&mut self, entry: Entry) {
        self.overlay = None;
        match load(&entry) {
            Ok(loaded) => self.install(entry, loaded),
            Err(e) => self.set_error(e),
        }
    }

    fn install(&mut self, entry: Entry, loaded: Loaded) {
        self.overlay = None;
        let Loaded {
            mission: m,
            text,
            name,
            path,
            errors,
        } = loaded;
        self.doc = Document::new(m, path)
            .with_source(text)
            .with_label(entry.label());
        // The jobs were of the other mission: not "stale", gone.
        for job in self.jobs.iter().filter(|j| j.is_running()) {
            job.cancel.cancel();
        }
        self.jobs.clear();
        self.job_cursor = 0;
        if let Some(r) = &mut self.recovery {
            // Opening another mission drops this one's unsaved edits
            // (the user was asked); its copy goes with them.
            r.discard();
            self.enable_recovery(match &entry {
                Entry::File(p) => Origin::File(p.clone()),
                Entry::Builtin(name) => Origin::Builtin((*name).to_owned()),
            });
        }
        self.selected = Item::Mission;
        self.field = 0;
        self.editing = None;
        self.camera.fit_map();
        self.shown_job = None;
        self.refresh();
        if errors > 0 {
            self.set_error(format!("opened {name}: {errors} error(s) to fix"));
        } else {
            self.set_status(format!("opened {name}"));
        }
    }
}

/// A mission read for opening, not yet in the designer.
struct Loaded {
    mission: Mission,
    text: String,
    name: String,
    path: Option<PathBuf>,
    errors: usize,
}

/// Reads and checks `entry`; the message names the file when it cannot be
/// opened (missing, a folder, not a mission).
fn load(entry: &Entry) -> Result<Loaded, String> {
    let (text, name, path) = match entry {
        Entry::File(p) => {
            if p.is_dir() {
                return Err(format!("cannot open {}: it is a folder", p.display()));
            }
            if !p.exists() {
                return Err(format!("cannot open {}: no such file", p.display()));
            }
            match mission::read(p) {
                Ok(text) => (text, p.display().to_string(), Some(p.clone())),
                Err(e) => return Err(e.to_string()),
            }
        }
        Entry::Builtin(name) => match mission::BUILTIN.iter().find(|b| b.file_name == *name) {
            Some(b) => (b.text.to_owned(), b.file_name.to_owned(), None),
            None => return Err(format!("no built-in mission {name}")),
        },
    };
    let checked = crate::diagnose::check_text(&text, Some(&name));
    match checked.mission {
        Some(mission) => Ok(Loaded {
            mission,
            errors: checked.report.error_count(),
            text,
            name,
            path,
        }),
        None => {
            let first = checked
                .report
                .errors()
                .next()
                .map(|d| d.to_string())
                .unwrap_or_default();
            Err(format!("cannot open {name}: {first}"))
        }
    }
}

/// Whether a diagnostic at `path` belongs to the field at `field`.
pub fn concerns(path: &str, field: &str) -> bool {
    path == field
        || path
            .strip_prefix(field)
            .is_some_and(|rest| rest.starts_with('.') || rest.starts_with('['))
}

/// The IWPs (eq. 9) of a mission whose only errors, if any, are in IWP
/// choices: those choices are left out, so the map still marks every IWP
/// while the user fixes the choice. Any other error: none.
fn iwps_despite_choices(m: &Mission, diagnostics: &[mission::Diagnostic]) -> Vec<Iwp> {
    use crate::mission::PathSegment;
    let mut bad = Vec::new();
    for d in diagnostics.iter().filter(|d| d.is_error()) {
        match d.path.0.as_slice() {
            [
                PathSegment::Key(r),
                PathSegment::Key(w),
                PathSegment::Index(i),
                ..,
            ] if r == "reconfiguration" && w == "waypoints" => bad.push(*i),
            _ => return Vec::new(),
        }
    }
    if bad.is_empty() {
        return find_iwps(m);
    }
    let mut clean = m.clone();
    let mut k = 0;
    clean.reconfiguration.waypoints.retain(|_| {
        k += 1;
        !bad.contains(&(k - 1))
    });
    find_iwps(&clean)
}

fn set_position(m: &mut Mission, item: &Item, p: Point2<f64>) {
    match item {
        Item::Obstacle(i) => {
            if let Some(o) = m.obstacles.get_mut(*i) {
                o.center = p;
            }
        }
        Item::Start => {
            m.route.start.x = p.x;
            m.route.start.y = p.y;
        }
        Item::Goal => {
            m.route.goal.x = p.x;
            m.route.goal.y = p.y;
        }
        Item::Slot(i) => {
            if let Some(s) = m.formation.slots.get_mut(*i) {
                s.x = p.x;
                s.y = p.y;
            }
        }
        Item::FleetTarget(i) => {
            if let Some(t) = m.fleet.targets.get_mut(*i) {
                t.position = p;
            }
        }
        _ => {}
    }
}

/// A file-name-friendly version of a mission name.
fn slug(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect();
    let s = s.trim_matches('-').to_owned();
    if s.is_empty() { "mission".into() } else { s }
}

/// The missions the open dialog offers: `*.toml` in `missions/` and the
/// current directory, then the built-in ones.
pub fn open_entries(cwd: &Path) -> Vec<Entry> {
    let mut files = Vec::new();
    for dir in [cwd.join("missions"), cwd.to_path_buf()] {
        if let Ok(read) = std::fs::read_dir(&dir) {
            for entry in read.flatten() {
                let p = entry.path();
                if p.extension().is_some_and(|e| e == "toml") && p.is_file() {
                    let shown = p.strip_prefix(cwd).map(Path::to_path_buf).unwrap_or(p);
                    files.push(shown);
                }
            }
        }
    }
    files.sort();
    files.dedup();
    let mut entries: Vec<Entry> = files
        .into_iter()
        .filter(|p| p.file_name().is_some_and(|n| n != "Cargo.toml"))
        .map(|p| Entry::File(if p.is_relative() { cwd.join(p) } else { p }))
        .collect();
    entries.extend(mission::BUILTIN.iter().map(|b| Entry::Builtin(b.file_name)));
    entries
}

/// A typed path, relative to `cwd` unless absolute (`~/` is the home folder).
pub fn typed_path(cwd: &Path, input: &str) -> PathBuf {
    let input = input.trim();
    if let Some(rest) = input.strip_prefix("~/")
        && let Some(home) = std::env::var_os("HOME")
    {
        return PathBuf::from(home).join(rest);
    }
    cwd.join(input)
}

/// What the open dialog lists for the text typed: the entries whose label
/// holds it (exact, then starting with it, then the rest), after the typed
/// path itself when it is a file not listed; just the typed path when
/// nothing matches (Enter then opens it, or says why not).
pub fn open_matches(entries: &[Entry], input: &str, cwd: &Path) -> Vec<Entry> {
    let wanted = input.trim().to_lowercase();
    if wanted.is_empty() {
        return entries.to_vec();
    }
    let typed = typed_path(cwd, input);
    let mut ranked: Vec<(u8, &Entry)> = entries
        .iter()
        .filter_map(|e| {
            let label = entry_label(e, cwd).to_lowercase();
            let file = match e {
                Entry::File(p) => p.file_name().map(|n| n.to_string_lossy().to_lowercase()),
                Entry::Builtin(n) => Some(n.to_lowercase()),
            };
            let rank = if label == wanted || matches!(e, Entry::File(p) if *p == typed) {
                0
            } else if label.starts_with(&wanted)
                || file.as_ref().is_some_and(|f| f.starts_with(&wanted))
            {
                1
            } else if label.contains(&wanted) {
                2
            } else {
                return None;
            };
            Some((rank, e))
        })
        .collect();
    ranked.sort_by_key(|(rank, _)| *rank);
    let mut matches: Vec<Entry> = ranked.into_iter().map(|(_, e)| e.clone()).collect();
    let listed = matches
        .iter()
        .any(|e| matches!(e, Entry::File(p) if *p == typed));
    if matches.is_empty() || (!listed && typed.is_file()) {
        matches.insert(0, Entry::File(typed));
    }
    matches
}

/// An entry as the open dialog shows it: files relative to `cwd`.
pub fn entry_label(entry: &Entry, cwd: &Path) -> String {
    match entry {
        Entry::File(p) => p.strip_prefix(cwd).unwrap_or(p).display().to_string(),
        other => other.label(),
    }
}

/// The formation's radius (for drawing and hit-testing slots).
pub fn formation_extent(m: &Mission) -> f64 {
    farthest_offset(&m.formation.slots).max(1.0)
}

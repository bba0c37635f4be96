//! The TUI's state and its one mutator, [`App::update`].
//!
//! Nothing here draws or reads the terminal: the view (`view/`) is a pure
//! function of this state, and input (`input.rs`) only produces actions, so
//! the whole app can be driven and checked in tests without a terminal.
//!
//! `App` composes components that own their state behind private fields:
//! the editor (`editor.rs`: document, selection, inspector), the job board
//! (`board.rs`), the overlays (`overlay.rs`), the camera (`camera.rs`) and
//! the fleet replay (`replay.rs`). It keeps what the screen as a whole is
//! in (focus, left pane, status line, quitting, working directory) and the
//! flows that cross components: saving, opening, showing and exporting a
//! result, the recovery copy. `update` hands every other action to the
//! component that owns it.
//!
//! Long (~970 lines) because it is the one `App`: the accessors the view draws from, the
//! dispatch of each action to its component, and the flows that cross components (find,
//! saving, opening, live runs, the recovery copy), which need more than one of them.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crossbeam_channel::Receiver;
use nalgebra::Point2;

use super::action::Action;
pub use super::action::{Focus, Pane};
use super::board::JobBoard;
use super::camera::Camera;
use super::document::{Document, slug};
use super::editor::{Editor, Request, Surroundings};
use super::fields::{Field, Item};
use super::find::{Before, Find};
use super::jobs::{Job, JobMsg};
pub use super::overlay::{AfterSave, Entry, Overlay};
use super::overlay::{Loaded, Overlays, load};
use super::recovery::{Origin, Recovery};
use super::replay::Replay;
pub use super::status::Status;
use super::status::StatusLine;
use crate::mission::{Mission, Preset};
use crate::pipelines::theta_pso::Iwp;

/// The whole TUI state.
pub struct App {
    /// The document, the selection and the inspector.
    editor: Editor,
    /// The runs, the one shown and how runs are recorded.
    board: JobBoard,
    /// The window on top, if any.
    overlays: Overlays,
    /// Zoom, pan and nudge step.
    camera: Camera,
    /// The fleet replay.
    replay: Replay,
    /// Find by name (`/`).
    find: Find,
    /// The recovery copy of unsaved edits; `None` unless enabled.
    recovery: Option<Recovery>,
    focus: Focus,
    pane: Pane,
    side_view: bool,
    status: StatusLine,
    should_quit: bool,
    /// Where relative paths (save as, open) start.
    cwd: PathBuf,
}

impl App {
    pub fn new(doc: Document, cwd: PathBuf) -> Self {
        App {
            editor: Editor::new(doc),
            board: JobBoard::default(),
            overlays: Overlays::default(),
            camera: Camera::default(),
            replay: Replay::default(),
            find: Find::default(),
            recovery: None,
            focus: Focus::Map,
            pane: Pane::Map,
            side_view: false,
            status: StatusLine::default(),
            should_quit: false,
            cwd,
        }
    }

    /// The document, the selection and the inspector.
    pub fn editor(&self) -> &Editor {
        &self.editor
    }

    /// The runs of this session.
    pub fn board(&self) -> &JobBoard {
        &self.board
    }

    /// Find by name: the prompt, or the matches being stepped through.
    pub fn finder(&self) -> &Find {
        &self.find
    }

    /// How the map and the formation editor are looked at.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    pub fn doc(&self) -> &Document {
        self.editor.doc()
    }

    pub fn mission(&self) -> &Mission {
        self.editor.mission()
    }

    /// The IWPs of the current mission (eq. 9); empty while it has errors.
    pub fn iwps(&self) -> &[Iwp] {
        self.editor.iwps()
    }

    pub fn selected(&self) -> &Item {
        self.editor.selected()
    }

    /// The inspector's fields for the selection.
    pub fn fields(&self) -> Vec<Field> {
        self.editor.fields()
    }

    /// The preset the slots are now (after any undo), if they are one.
    pub fn current_preset(&self) -> Option<Preset> {
        self.editor.current_preset()
    }

    pub fn jobs(&self) -> &[Job] {
        self.board.jobs()
    }

    /// The job whose result is on the map.
    pub fn shown(&self) -> Option<&Job> {
        self.board.shown()
    }

    /// The window on top, if any.
    pub fn overlay(&self) -> Option<&Overlay> {
        self.overlays.current()
    }

    /// First line of the help overlay shown.
    pub fn help_scroll(&self) -> u16 {
        self.overlays.help_scroll()
    }

    pub fn status(&self) -> Option<&Status> {
        self.status.get()
    }

    pub fn focus(&self) -> Focus {
        self.focus
    }

    pub fn pane(&self) -> Pane {
        self.pane
    }

    /// The map pane shows the side view (x–z) instead of the top view.
    pub fn side_view(&self) -> bool {
        self.side_view
    }

    pub fn should_quit(&self) -> bool {
        self.should_quit
    }

    /// Where relative paths (save as, open) start.
    pub fn cwd(&self) -> &Path {
        &self.cwd
    }

    /// An error for the status line from outside the app (the designer's
    /// start: a mission that could not be read).
    pub fn show_error(&mut self, text: impl Into<String>) {
        self.status.error(text);
    }

    /// The channel the main loop waits on, next to input.
    pub fn job_messages(&self) -> &Receiver<JobMsg> {
        self.board.messages()
    }

    pub fn step_size(&self) -> f64 {
        self.camera.step_size()
    }

    /// Whether the fleet replay is playing.
    pub fn is_playing(&self) -> bool {
        self.replay.is_playing()
    }

    /// Lists a job that runs elsewhere (a run planned synchronously for a
    /// test or the benchmark); its messages come through `on_job_msg`.
    pub fn adopt_job(&mut self, job: Job) {
        self.board.adopt(job);
    }

    /// A result is stale when the mission changed after its run started.
    pub fn is_stale(&self, job: &Job) -> bool {
        &job.mission != self.mission()
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
            .filter(|o| o.kind().words().fixed_wing)
        {
            for p in o
                .reference_tracks()
                .iter()
                .chain(&o.tracks())
                .flat_map(|t| &t.samples)
                .map(|s| s.position)
            {
                x = [x[0].min(p.x), x[1].max(p.x)];
                y = [y[0].min(p.y), y[1].max(p.y)];
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
        self.shown()?.outcome.as_ref()?.face().replay()
    }

    /// The fleet replay instant on the map: the replay cursor, or the end.
    pub fn replay_time(&self) -> Option<f64> {
        self.replay_end().map(|end| self.replay.time(end))
    }

    /// The loop needs to wake up by itself (running jobs, a playing replay).
    pub fn wants_tick(&self) -> bool {
        self.board.any_running() || self.replay.is_playing() || self.recovery_pending()
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
                self.overlays.show(Overlay::Recover(Box::new(copy)));
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
        let doc = self.editor.doc();
        self.recovery
            .as_ref()
            .is_some_and(|r| r.pending(doc.mission(), doc.is_modified()))
    }

    /// Brings the recovery copy in line with the document (after every
    /// action and tick; `force` on the way out). Left alone while the
    /// restore question is open, so an earlier copy is never overwritten
    /// before the user answers.
    pub fn keep_recovery(&mut self, now: Instant, force: bool) {
        if matches!(self.overlay(), Some(Overlay::Recover(_))) {
            return;
        }
        let Some(r) = &mut self.recovery else {
            return;
        };
        let doc = self.editor.doc();
        let had_failed = r.failed.is_some();
        r.keep(doc.mission(), doc.is_modified(), doc.changes(), now, force);
        if let (false, Some(e)) = (had_failed, r.failed.clone()) {
            self.status.error(e);
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

    /// Changes state for one action, handed to the component that owns it.
    /// Never panics on user input.
    pub fn update(&mut self, action: Action) {
        use Action::*;
        match action {
            Quit | Dismiss | FocusNext | FocusPrevious | FocusOn(_) | ShowMap | ShowFormation
            | ToggleSideView => self.update_screen(action),
            ToggleHelp | ScrollHelp(_) | PromptInput(_) | PromptClear | PromptBackspace
            | PickerMove(_) => self.overlays.update(action, &self.cwd),
            Save | SaveAs | Open | Confirm | Import => self.update_files(action),
            ChangeStep(_) | Zoom(..) | Pan(..) | Fit => self.update_camera(action),
            Find | FindInput(_) | FindBackspace | FindClear | FindStep(_) | FindKeep
            | FindCancel => self.update_find(action),
            Scrub(_) | TogglePlay => self.update_replay(action),
            Run(_) | RunDistributed(_) | FlightCheck | RunNewSeed | Cancel | JobUp | JobDown
            | ToggleRecording | CycleViewer => {
                self.board
                    .update(action, self.editor.doc(), &self.cwd, &mut self.status)
            }
            ToggleLive => {
                self.board.toggle_live(Instant::now(), &mut self.status);
                let live = self.board.live();
                if live.is_on() {
                    let over = crate::outcome::over_live_limits(live.pipeline(), self.mission());
                    if !over.is_empty() {
                        self.status.say(format!(
                            "live planning on: {}, re-plans may take seconds",
                            over.join(", ")
                        ));
                    }
                }
                self.poll_live(Instant::now());
            }
            ShowJob => {
                if self.board.show_selected() {
                    self.pane = Pane::Map;
                }
            }
            Export => {
                let doc = self.editor.doc();
                match super::export::export_shown(self.board.shown(), doc, &self.cwd) {
                    Ok(text) => self.status.say(text),
                    Err(text) => self.status.error(text),
                }
            }
            SelectNext | SelectPrevious | Select(_) | Nudge(..) | AddObstacle(_) | AddVia
            | ToggleAddTool | Duplicate | Delete | AddSlot | CyclePreset | CycleShape
            | ToggleWaypoint | ToggleInspect | ToggleVertices | FieldUp | FieldDown
            | EditStart(_) | EditInput(_) | EditBackspace | EditClear | EditCommit | EditCancel
            | Undo | Redo | DragStart(..) | DragTo(_) | DragEnd => self.update_editor(action),
        }
        // Whatever changed the mission (an edit, an undo, an import, an
        // open), live planning follows it.
        self.board.follow(self.editor.doc(), Instant::now());
    }

    /// Live planning on, for θ-PSO, when the mission is of a size planned
    /// in well under a second (the designer's start; tests leave it off);
    /// else off, and the status line says which size keeps it off.
    pub fn enable_live(&mut self) {
        let over =
            crate::outcome::over_live_limits(crate::pipelines::Kind::default(), self.mission());
        if !over.is_empty() {
            self.hold_live_off(format!("{}; L turns it on", over.join(", ")));
            return;
        }
        let now = Instant::now();
        if self
            .board
            .start_live(crate::pipelines::Kind::default(), now)
            .is_ok()
        {
            self.board.follow(self.editor.doc(), now);
        }
    }

    /// Leaves live planning off for `why` (the designer's start: the
    /// mission's size, `--no-live`); the status line says so unless it
    /// already has something to say, and the empty jobs panel says so too.
    pub fn hold_live_off(&mut self, why: String) {
        let text = format!("live planning off: {why}");
        if self.status.get().is_none() {
            self.status.say(text.clone());
        }
        self.board.hold_live_off(text);
    }

    /// Live planning on for `pipeline` (θ-PSO or FLATLO), whatever the size.
    pub fn start_live(&mut self, pipeline: crate::pipelines::Kind) -> Result<(), String> {
        let now = Instant::now();
        self.board.start_live(pipeline, now)?;
        self.board.follow(self.editor.doc(), now);
        Ok(())
    }

    /// Does what the designer's loop does for live planning (starts the
    /// run due, applies the runs' messages) until nothing is due or under
    /// way: tests and the live benchmark. False on timeout.
    pub fn settle_live(&mut self, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        loop {
            let now = Instant::now();
            if self.wake_at().is_some_and(|at| at <= now) {
                self.poll_live(now);
                continue;
            }
            let live = self.board.live();
            if live.due().is_none() && !live.any_running() {
                self.drain_job_messages();
                return true;
            }
            if now >= deadline {
                return false;
            }
            let wait = self
                .wake_at()
                .map_or(deadline - now, |at| at.saturating_duration_since(now))
                .min(deadline - now);
            if let Ok(msg) = self.board.messages().recv_timeout(wait) {
                self.on_job_msg(msg, Instant::now());
            }
        }
    }

    /// Starts the live run that is due by `now`, if one is.
    pub fn poll_live(&mut self, now: Instant) {
        self.board.poll_live(self.editor.doc(), now);
    }

    /// When the loop must wake by itself next (a live run due), if ever.
    pub fn wake_at(&self) -> Option<Instant> {
        self.board.live().due()
    }

    /// Quitting, closing, focus and what the left pane shows.
    fn update_screen(&mut self, action: Action) {
        match action {
            Action::Quit => {
                if self.editor.doc().is_modified() {
                    self.overlays.show(Overlay::Quit);
                } else if self.board.any_running() {
                    // A run would be lost without a word: ask.
                    self.overlays.show(Overlay::QuitRunning);
                } else {
                    self.shutdown();
                }
            }
            Action::Dismiss if matches!(self.overlay(), Some(Overlay::Recover(_))) => {
                self.overlays.close();
                if let Some(r) = &mut self.recovery {
                    r.discard();
                }
                self.status.say("the recovery copy was discarded");
            }
            Action::Dismiss => {
                // The innermost first: the line typed, the window, a find,
                // the add tool.
                let closed = self.editor.cancel_edit() || self.overlays.close();
                if !closed {
                    if self.find.end() {
                        self.status
                            .say("find ended: n / p step through every item again");
                    } else {
                        self.editor.stop_add_tool();
                    }
                }
            }
            Action::FocusNext | Action::FocusPrevious => {
                self.editor.cancel_edit();
                let order = [Focus::Map, Focus::Inspector, Focus::Jobs];
                let i = order.iter().position(|f| *f == self.focus).unwrap_or(0);
                let d = if action == Action::FocusNext {
                    1
                } else {
                    order.len() - 1
                };
                self.focus = order[(i + d) % order.len()];
            }
            Action::FocusOn(focus) => {
                if focus != self.focus {
                    self.editor.cancel_edit();
                }
                self.focus = focus;
            }
            Action::ShowMap => {
                self.pane = Pane::Map;
                self.editor.keep_selection_in(Pane::Map);
            }
            Action::ShowFormation => {
                self.pane = Pane::Formation;
                self.side_view = false;
                self.editor.keep_selection_in(Pane::Formation);
            }
            Action::ToggleSideView if self.pane == Pane::Map => {
                self.side_view = !self.side_view;
            }
            _ => {}
        }
    }

    fn update_camera(&mut self, action: Action) {
        match action {
            Action::ChangeStep(d) => {
                self.camera.change_step(d);
                self.status.say(format!(
                    "nudge step {} m",
                    super::fields::fmt_num(self.step_size())
                ));
            }
            Action::Zoom(factor, at) => match self.pane {
                Pane::Map => {
                    let extent = self.map_extent();
                    self.camera.zoom_map(factor, at, extent);
                }
                Pane::Formation => self.camera.zoom_formation(factor),
            },
            Action::Pan(fx, fy) => {
                let extent = self.map_extent();
                self.camera.pan(fx, fy, extent);
            }
            Action::Fit => match self.pane {
                Pane::Map => self.camera.fit_map(),
                Pane::Formation => self.camera.fit_formation(),
            },
            _ => {}
        }
    }

    /// The find prompt and its matches: typing narrows them and selects
    /// the first (the map pans to it), Enter keeps it, Esc goes back.
    fn update_find(&mut self, action: Action) {
        match action {
            Action::Find => {
                self.editor.cancel_edit();
                self.find.start(Before {
                    selected: self.selected().clone(),
                    center: self.camera.panned_center(),
                    pane: self.pane,
                });
            }
            Action::FindInput(c) => self.find_query(format!("{}{c}", self.find.query())),
            Action::FindBackspace => {
                let mut query = self.find.query().to_owned();
                query.pop();
                self.find_query(query);
            }
            Action::FindClear => self.find_query(String::new()),
            Action::FindStep(by) => {
                if !self.find.is_typing() {
                    let (m, iwps) = (self.editor.mission(), self.editor.iwps());
                    self.find.refresh(m, iwps, self.editor.selected());
                }
                match self.find.step(by).cloned() {
                    Some(item) => {
                        self.go_to(item);
                        if !self.find.is_typing() {
                            self.say_match();
                        }
                    }
                    None if !self.find.is_typing() => {
                        self.find.end();
                        self.status.say("no match left: the find ended");
                    }
                    None => {}
                }
            }
            Action::FindKeep => {
                let query = self.find.query().trim().to_owned();
                if self.find.current().is_none() {
                    self.find_cancel();
                    if !query.is_empty() {
                        self.status
                            .error(format!("no obstacle or IWP has '{query}' in its name"));
                    }
                    return;
                }
                self.find.keep();
                self.say_match();
                // One match: nothing to step through, n and p select as ever.
                if self.find.matches().len() == 1 {
                    self.find.end();
                }
            }
            Action::FindCancel => self.find_cancel(),
            _ => {}
        }
    }

    /// The find's query is now `query`: its first match is selected, or,
    /// with none, what was before the find.
    fn find_query(&mut self, query: String) {
        let (m, iwps) = (self.editor.mission(), self.editor.iwps());
        self.find.set_query(query, m, iwps);
        match self.find.current().cloned() {
            Some(item) => self.go_to(item),
            None => {
                if let Some(before) = self.find.before().cloned() {
                    self.restore(before);
                }
            }
        }
    }

    fn find_cancel(&mut self) {
        if let Some(before) = self.find.cancel() {
            self.restore(before);
        }
    }

    /// Back to what was on screen before a find.
    fn restore(&mut self, before: Before) {
        self.update_editor(Action::Select(before.selected));
        self.camera.look_at(before.center);
        self.pane = before.pane;
    }

    /// Selects `item` and shows it: an obstacle on the map, panned to
    /// unless the whole map is in view; an IWP where it is (the map or the
    /// formation editor's table).
    fn go_to(&mut self, item: Item) {
        let at = match &item {
            Item::Obstacle(i) => self.mission().obstacles.get(*i).map(|o| o.center),
            Item::Waypoint(between) => self
                .iwps()
                .iter()
                .find(|w| w.between == *between)
                .map(|w| w.position),
            _ => None,
        };
        if matches!(item, Item::Obstacle(_)) {
            self.pane = Pane::Map;
        }
        self.update_editor(Action::Select(item));
        if self.pane == Pane::Map
            && !self.camera.shows_everything()
            && let Some(p) = at
        {
            self.camera.look_at(Some(p));
        }
    }

    /// The status line names the match selected, which of how many, and
    /// the keys that step on.
    fn say_match(&mut self) {
        let Some(item) = self.find.current() else {
            return;
        };
        let n = self.find.matches().len();
        let title = item.title(self.mission());
        let query = self.find.query().trim();
        self.status.say(if n == 1 {
            format!("{title}: the one match for '{query}'")
        } else {
            format!(
                "{title}: {} of {n} matches for '{query}' (n / N next / previous, Esc ends the find)",
                self.find.cursor() + 1
            )
        });
    }

    fn update_replay(&mut self, action: Action) {
        let Some(end) = self.replay_end() else {
            return;
        };
        match action {
            Action::Scrub(seconds) => self.replay.scrub(seconds, end),
            Action::TogglePlay => self.replay.toggle(end),
            _ => {}
        }
    }

    fn update_editor(&mut self, action: Action) {
        let around = Surroundings {
            pane: self.pane,
            step: self.camera.step_size(),
            panned_center: self.camera.panned_center(),
        };
        match self.editor.update(action, &around, &mut self.status) {
            Some(Request::ShowMap) => self.pane = Pane::Map,
            Some(Request::FocusInspector) => self.focus = Focus::Inspector,
            None => {}
        }
    }

    /// Save, save as, open, and "yes" to the window on top.
    fn update_files(&mut self, action: Action) {
        match action {
            Action::Save => match self.overlay() {
                Some(Overlay::Quit) => self.save(None, AfterSave::Quit, false),
                Some(Overlay::Discard(entry)) => {
                    let then = AfterSave::Open(entry.clone());
                    self.save(None, then, false);
                }
                _ => self.save(None, AfterSave::Stay, false),
            },
            Action::SaveAs => {
                // Pre-filled relative to the working directory when it can be.
                let input = self
                    .doc()
                    .path()
                    .map(|p| p.strip_prefix(&self.cwd).unwrap_or(p).display().to_string())
                    .unwrap_or_else(|| format!("{}.toml", slug(&self.mission().name)));
                self.overlays.show(Overlay::SaveAs {
                    input,
                    then: AfterSave::Stay,
                });
            }
            Action::Open => self.overlays.open_dialog(&self.cwd),
            Action::Import => self.overlays.show(Overlay::Import {
                input: String::new(),
            }),
            Action::Confirm => self.confirm(),
            _ => {}
        }
    }

    /// Quits without asking (a signal: the terminal is closing or the
    /// process is told to stop). Unsaved edits stay in the recovery copy.
    pub fn quit_now(&mut self) {
        self.keep_recovery(Instant::now(), true);
        self.shutdown();
    }

    /// How many jobs are running (quitting cancels them).
    pub fn running_jobs(&self) -> usize {
        self.board.jobs().iter().filter(|j| j.is_running()).count()
    }

    /// Cancels running jobs (they return their best at once) and stops.
    fn shutdown(&mut self) {
        self.board.cancel_all();
        self.should_quit = true;
    }

    /// Applies a worker's message (`now` stamps job ends); a finished run's
    /// result is shown, its replay from the end.
    pub fn on_job_msg(&mut self, msg: JobMsg, now: Instant) {
        if self.board.on_msg(msg, now, &mut self.status) {
            self.replay.reset();
        }
    }

    /// Applies every message already waiting; returns whether there was any.
    pub fn drain_job_messages(&mut self) -> bool {
        let mut any = false;
        while let Ok(msg) = self.board.messages().try_recv() {
            self.on_job_msg(msg, Instant::now());
            any = true;
        }
        any
    }

    /// Blocks until no job runs (tests, headless use). False on timeout.
    pub fn wait_for_jobs(&mut self, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        while self.board.any_running() {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.board.messages().recv_timeout(left) {
                Ok(msg) => self.on_job_msg(msg, Instant::now()),
                Err(_) => return false,
            }
        }
        self.drain_job_messages();
        true
    }

    fn save(&mut self, path: Option<PathBuf>, then: AfterSave, confirmed: bool) {
        let target = path.or_else(|| self.doc().path().map(Path::to_path_buf));
        let Some(target) = target else {
            self.overlays.show(Overlay::SaveAs {
                input: format!("{}.toml", slug(&self.mission().name)),
                then,
            });
            return;
        };
        let errors = self.doc().error_lines();
        if !errors.is_empty() && !confirmed {
            self.overlays.show(Overlay::SaveInvalid {
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
            self.overlays.close();
            self.status
                .error(format!("not saved: cannot create {}: {e}", dir.display()));
            return;
        }
        let before = self.doc().path().map(Path::to_path_buf);
        match self.editor.save(target) {
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
                self.overlays.close();
                let saved = format!("saved {}", p.display());
                self.status.say(saved.clone());
                match then {
                    AfterSave::Stay => {}
                    AfterSave::Quit => self.shutdown(),
                    AfterSave::Open(entry) => {
                        self.open(entry);
                        self.status.prefix(&saved);
                    }
                }
            }
            Err(e) => {
                self.overlays.close();
                self.status.error(format!("not saved: {e}"));
            }
        }
    }

    /// "Yes" to the window on top.
    fn confirm(&mut self) {
        match self.overlay().cloned() {
            Some(Overlay::Quit) => {
                // Quit without saving: the user chose to drop the changes, so
                // no copy may be written on the way out either.
                self.overlays.close();
                if let Some(mut r) = self.recovery.take() {
                    r.discard();
                }
                self.shutdown();
            }
            Some(Overlay::QuitRunning) => {
                self.overlays.close();
                self.shutdown();
            }
            Some(Overlay::SaveAs { input, then }) => {
                let input = input.trim();
                if input.is_empty() {
                    self.status.error("type a file name");
                    return;
                }
                let path = self.cwd.join(input);
                let current = self.doc().path().map(|p| self.cwd.join(p));
                if path.exists() && current.as_ref() != Some(&path) {
                    self.overlays.show(Overlay::Overwrite { path, then });
                    return;
                }
                self.save(Some(path), then, false);
            }
            Some(Overlay::Overwrite { path, then }) => self.save(Some(path), then, false),
            Some(Overlay::Recover(copy)) => {
                self.overlays.close();
                let changes = copy.changes;
                self.editor.restore(copy.mission);
                self.status.say(format!(
                    "restored {changes} unsaved change(s); Ctrl-s saves them, u undoes the restore"
                ));
            }
            Some(Overlay::SaveInvalid { path, then, .. }) => self.save(path, then, true),
            Some(Overlay::Open {
                matches, cursor, ..
            }) => {
                let Some(entry) = matches.get(cursor).cloned() else {
                    self.status
                        .error("nothing to open: type a path or pick a listed mission");
                    return;
                };
                // A file that cannot be opened is refused here, before the
                // unsaved-changes question; the dialog stays to fix the path.
                match load(&entry) {
                    Err(e) => self.status.error(e),
                    Ok(_) if self.doc().is_modified() => {
                        self.overlays.show(Overlay::Discard(entry));
                    }
                    Ok(loaded) => self.install(entry, loaded),
                }
            }
            Some(Overlay::Discard(entry)) => self.open(entry),
            Some(Overlay::Import { input }) => {
                self.overlays.close();
                super::import::import(&mut self.editor, &self.cwd, &input, &mut self.status);
            }
            Some(Overlay::Help) | None => {}
        }
    }

    /// Replaces the document with another mission. A file that cannot be
    /// read as a mission at all is refused (the status says why, naming
    /// it, and the document stays); one with validation errors opens (the
    /// inspector shows them).
    pub fn open(&mut self, entry: Entry) {
        self.overlays.close();
        match load(&entry) {
            Ok(loaded) => self.install(entry, loaded),
            Err(e) => self.status.error(e),
        }
    }

    fn install(&mut self, entry: Entry, loaded: Loaded) {
        self.overlays.close();
        let Loaded {
            mission: m,
            text,
            name,
            path,
            errors,
            new,
        } = loaded;
        let doc = match (&entry, path) {
            (Entry::New(p), _) => Document::new_file(m, p.clone()),
            (_, path) => Document::new(m, path),
        }
        .with_source(text);
        let doc = match &entry {
            Entry::Builtin(name) => doc.with_builtin(name),
            Entry::File(_) | Entry::New(_) => doc.with_label(entry.label()),
        };
        // The jobs were of the other mission: not "stale", gone; so are
        // the matches of a find.
        self.board.clear();
        self.find.end();
        self.editor.replace(doc);
        if let Some(r) = &mut self.recovery {
            // Opening another mission drops this one's unsaved edits
            // (the user was asked); its copy goes with them.
            r.discard();
            self.enable_recovery(match &entry {
                Entry::File(p) | Entry::New(p) => Origin::File(p.clone()),
                Entry::Builtin(name) => Origin::Builtin((*name).to_owned()),
            });
        }
        self.camera.fit_map();
        if new {
            self.status.say(format!(
                "new mission {name} (a box, a start, a goal): Ctrl-s creates the file"
            ));
        } else if errors > 0 {
            self.status
                .error(format!("opened {name}: {errors} error(s) to fix"));
        } else {
            self.status.say(format!("opened {name}"));
        }
    }
}

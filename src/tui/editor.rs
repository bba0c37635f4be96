//! The document and the inspector as one component: the mission being
//! edited (with its undo history), the IWPs found in it, what is selected,
//! the inspector's field cursor and the line being typed, the add tool, the
//! formation preset and a drag in progress.
//!
//! One component because every edit goes through the selection (a nudge
//! moves the selected item, the inspector edits its fields) and every edit
//! must leave the selection valid and the IWPs current ([`Editor::refresh`]).
//! The rest of the screen reaches it through [`Editor::update`] and reads it
//! through its accessors.
//!
//! Long (~970 lines) because every edit the designer offers is a method here (add,
//! duplicate, delete, nudge, drag, presets, shapes, undo, the inspector's typed line), each
//! going through the selection and leaving it and the IWPs current.

use std::path::PathBuf;

use nalgebra::{Point2, Vector2};

use super::action::{Action, Pane};
use super::document::Document;
use super::fields::{self, Field, Item};
use super::status::StatusLine;
use crate::mission::{self, Mission, MissionError, PathSegment, Preset, Severity, ShapeChoice};
use crate::pipelines::points::{self, PointRef};
use crate::pipelines::theta_pso::{Iwp, find_iwps};

/// A line of text being typed into an inspector field.
#[derive(Debug, Clone, PartialEq)]
pub struct Editing {
    pub buffer: String,
    /// Why the text cannot be used, or the validation message it would cause
    /// (updated on every key).
    pub problem: Option<(Severity, String)>,
}

/// A drag in progress: the item and where it was grabbed relative to its position.
#[derive(Debug, Clone, PartialEq)]
struct Drag {
    item: Item,
    grab: Vector2<f64>,
}

/// What the editor needs to know of the screen around it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surroundings {
    /// The left pane on screen (which items n/p cycle through).
    pub pane: Pane,
    /// The nudge step, metres (nudges and drags snap to it).
    pub step: f64,
    /// Where the map looks, when it was panned (a new obstacle goes there).
    pub panned_center: Option<Point2<f64>>,
}

/// What an action of the editor asks of the screen around it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Request {
    /// Show the map (an obstacle was added).
    ShowMap,
    /// Focus the inspector (typing into a field began).
    FocusInspector,
}

pub struct Editor {
    doc: Document,
    /// The IWPs of the current mission (eq. 9), refreshed on every change;
    /// empty while the mission has errors.
    iwps: Vec<Iwp>,
    selected: Item,
    /// Inspector cursor.
    field: usize,
    editing: Option<Editing>,
    /// Clicking an empty spot of the map places an obstacle.
    add_tool: bool,
    preset: Preset,
    drag: Option<Drag>,
}

impl Editor {
    pub fn new(doc: Document) -> Self {
        let mut editor = Editor {
            doc,
            iwps: Vec::new(),
            selected: Item::Mission,
            field: 0,
            editing: None,
            add_tool: false,
            preset: Preset::Triangle,
            drag: None,
        };
        editor.refresh();
        editor
    }

    pub fn doc(&self) -> &Document {
        &self.doc
    }

    pub fn mission(&self) -> &Mission {
        self.doc.mission()
    }

    pub fn iwps(&self) -> &[Iwp] {
        &self.iwps
    }

    pub fn selected(&self) -> &Item {
        &self.selected
    }

    /// The inspector's cursor: an index into [`Editor::fields`].
    pub fn field(&self) -> usize {
        self.field
    }

    pub fn editing(&self) -> Option<&Editing> {
        self.editing.as_ref()
    }

    pub fn add_tool(&self) -> bool {
        self.add_tool
    }

    /// The inspector's fields for the selection.
    pub fn fields(&self) -> Vec<Field> {
        fields::fields(&self.selected, self.mission())
    }

    /// Another document (a mission opened): the selection goes back to the
    /// mission item, and a drag or the add tool of the old one stops (its
    /// item may not exist in the new one).
    pub fn replace(&mut self, doc: Document) {
        self.doc = doc;
        self.selected = Item::Mission;
        self.field = 0;
        self.editing = None;
        self.drag = None;
        self.add_tool = false;
        self.refresh();
    }

    /// Puts `mission` in place of the document's as one undo step (the
    /// recovery copy, restored).
    pub fn restore(&mut self, mission: Mission) {
        self.doc.edit(|m| *m = mission);
        self.refresh();
    }

    /// Saves the document to `path` (which becomes its file).
    pub fn save(&mut self, path: PathBuf) -> Result<PathBuf, MissionError> {
        self.doc.save(Some(path))
    }

    /// Stops typing into a field; false if nothing was being typed.
    pub fn cancel_edit(&mut self) -> bool {
        self.editing.take().is_some()
    }

    pub fn stop_add_tool(&mut self) {
        self.add_tool = false;
    }

    /// Keeps the selection among the items `pane` shows (the map's when it
    /// is not one of them, the formation's likewise).
    pub fn keep_selection_in(&mut self, pane: Pane) {
        let (items, fallback) = match pane {
            Pane::Map => (fields::map_items(self.mission()), Item::Bounds),
            Pane::Formation => (
                fields::formation_items(self.mission(), &self.iwps),
                Item::Formation,
            ),
        };
        if !items.contains(&self.selected) {
            self.select(fallback);
        }
    }

    /// Changes the document, the selection or the inspector for one action
    /// (the others are not the editor's and change nothing here).
    pub fn update(
        &mut self,
        action: Action,
        around: &Surroundings,
        status: &mut StatusLine,
    ) -> Option<Request> {
        use Action::*;
        match action {
            SelectNext => self.select_step(around.pane, true),
            SelectPrevious => self.select_step(around.pane, false),
            Select(item) => self.select(item),
            Nudge(dx, dy) => self.nudge(dx, dy, around.step, status),
            AddObstacle(at) => {
                let p = at
                    .or(around.panned_center)
                    .unwrap_or(self.mission().bounds.center_xy());
                self.add_obstacle(p, status);
                return Some(Request::ShowMap);
            }
            ToggleAddTool => {
                self.add_tool = !self.add_tool;
                status.say(if self.add_tool {
                    "add tool: click an empty spot of the map to place an obstacle (Esc to stop)"
                } else {
                    "add tool off"
                });
            }
            Duplicate => self.duplicate(status),
            AddVia => {
                let p = around
                    .panned_center
                    .unwrap_or(self.mission().bounds.center_xy());
                self.add_via(p, status);
                return Some(Request::ShowMap);
            }
            ToggleInspect => self.toggle_inspect(status),
            ToggleVertices => self.toggle_vertices(status),
            Delete => self.delete(status),
            AddSlot => self.add_slot(status),
            CyclePreset => self.cycle_preset(status),
            CycleShape => self.cycle_shape(status),
            ToggleWaypoint => {
                if let Item::Waypoint(between) = &self.selected {
                    let (item, between) = (self.selected.clone(), between.clone());
                    self.edit(status, |m| {
                        if let Ok(choice) = fields::waypoint_choice(m, &item) {
                            choice.enabled = !choice.enabled;
                        }
                    });
                    status.say(self.iwp_said(&between));
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
                return self.start_editing(first).then_some(Request::FocusInspector);
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
            EditClear => {
                if let Some(e) = &mut self.editing {
                    e.buffer.clear();
                    self.check_editing();
                }
            }
            EditCommit => self.commit_edit(status),
            EditCancel => self.editing = None,
            Undo => self.step_history(true, status),
            Redo => self.step_history(false, status),
            DragStart(item, at) => self.drag_start(item, at),
            DragTo(at) => self.drag_to(at, around.step),
            DragEnd => self.drag_end(),
            _ => {}
        }
        None
    }

    /// After any change to the mission: keep the selection valid, recompute IWPs.
    fn refresh(&mut self) {
        let m = self.doc.mission();
        self.iwps = iwps_despite_choices(m, &self.doc.revision());
        if !self.selected.exists(m) {
            self.selected = match self.selected {
                Item::Vertex(i, _) if i < m.obstacles.len() => Item::Obstacle(i),
                Item::Obstacle(_) | Item::Vertex(_, _) if !m.obstacles.is_empty() => {
                    Item::Obstacle(m.obstacles.len() - 1)
                }
                Item::Slot(_) | Item::Waypoint(_) => Item::Formation,
                _ => Item::Bounds,
            };
        }
        let n = fields::fields(&self.selected, m).len();
        self.field = self.field.min(n.saturating_sub(1));
    }

    /// One undo step; the status line moves on from an old error.
    fn edit(&mut self, status: &mut StatusLine, change: impl FnOnce(&mut Mission)) {
        self.doc.edit(change);
        status.clear_error();
        self.refresh();
    }

    fn select(&mut self, item: Item) {
        if item != self.selected {
            self.editing = None;
            self.field = 0;
        }
        self.selected = item;
    }

    /// The next (or previous) item of those `pane` shows; from a vertex,
    /// the next (previous) vertex of its footprint.
    fn select_step(&mut self, pane: Pane, forward: bool) {
        if let Item::Vertex(i, v) = self.selected {
            let n = self
                .mission()
                .obstacles
                .get(i)
                .map_or(0, |o| o.footprint.len());
            if n > 0 {
                let next = if forward {
                    (v + 1) % n
                } else {
                    (v + n - 1) % n
                };
                self.select(Item::Vertex(i, next));
            }
            return;
        }
        let items = match pane {
            Pane::Map => fields::map_items(self.mission()),
            Pane::Formation => fields::formation_items(self.mission(), &self.iwps),
        };
        if items.is_empty() {
            return;
        }
        let i = items.iter().position(|it| *it == self.selected);
        let n = items.len();
        let next = match (i, forward) {
            (Some(i), true) => (i + 1) % n,
            (Some(i), false) => (i + n - 1) % n,
            (None, _) => 0,
        };
        self.select(items[next].clone());
    }

    fn add_obstacle(&mut self, p: Point2<f64>, status: &mut StatusLine) {
        let obstacle = fields::new_obstacle(self.mission(), p);
        let name = obstacle.name.clone();
        self.edit(status, |m| m.obstacles.push(obstacle));
        let i = self.mission().obstacles.len() - 1;
        self.select(Item::Obstacle(i));
        status.say(format!("added '{name}' at ({:.1}, {:.1})", p.x, p.y));
    }

    /// A copy of the selected obstacle beside it, or a new point of the
    /// selected point's kind (or of its section's first kind) after the
    /// last.
    fn duplicate(&mut self, status: &mut StatusLine) {
        let kind = match &self.selected {
            Item::Point(p) => Some((p.pipeline, p.kind)),
            Item::Section(k) => points::kinds_of(*k).next().map(|(i, _)| (*k, i)),
            _ => None,
        };
        if let Some((pipeline, kind)) = kind
            && let Some(k) = pipeline.face().points().get(kind)
        {
            self.edit(status, |m| (k.add)(m));
            let index = (k.count)(self.mission()).saturating_sub(1);
            self.select(Item::Point(PointRef {
                pipeline,
                kind,
                index,
            }));
            return;
        }
        match self.selected {
            Item::Obstacle(i) => {
                if let Some(o) = self.mission().obstacles.get(i) {
                    let copy = fields::duplicate_obstacle(self.mission(), o);
                    self.edit(status, |m| m.obstacles.push(copy));
                    self.select(Item::Obstacle(self.mission().obstacles.len() - 1));
                }
            }
            Item::Vertex(i, v) => {
                let Some(o) = self.mission().obstacles.get(i) else {
                    return;
                };
                let n = o.footprint.len();
                if n == 0 || v >= n {
                    return;
                }
                // Halfway to the next vertex: the outline keeps its shape.
                let mid = nalgebra::center(&o.footprint[v], &o.footprint[(v + 1) % n])
                    .map(mission::round_mm);
                self.edit(status, |m| {
                    let o = &mut m.obstacles[i];
                    o.footprint.insert(v + 1, mid);
                    o.settle();
                });
                self.select(Item::Vertex(i, v + 1));
                status.say(format!(
                    "vertex {} added at ({:.1}, {:.1})",
                    v + 2,
                    mid.x,
                    mid.y
                ));
            }
            _ => {}
        }
    }

    /// A footprint's first vertex, or from a vertex its footprint.
    fn toggle_vertices(&mut self, status: &mut StatusLine) {
        match self.selected {
            Item::Obstacle(i) => {
                let Some(o) = self.mission().obstacles.get(i) else {
                    return;
                };
                if o.footprint.is_empty() {
                    status.say("a cylinder has no corners: select a footprint (a building, a bay)");
                    return;
                }
                let (n, name) = (o.footprint.len(), o.name.clone());
                self.select(Item::Vertex(i, 0));
                status.say(format!(
                    "vertex 1 of {n} of '{name}': n/p step, arrows or drag move, d adds one, Del deletes, c back"
                ));
            }
            Item::Vertex(i, _) => self.select(Item::Obstacle(i)),
            _ => status.say("select a footprint to edit its corners"),
        }
    }

    /// `g`: a place the route must take. With an obstacle selected, the gap
    /// between it and the nearest obstacle in the altitude band (a gate:
    /// change either name in the inspector); else a point at `at`, at the
    /// start's altitude. Selected, to edit; `Del` removes it.
    fn add_via(&mut self, at: Point2<f64>, status: &mut StatusLine) {
        let m = self.mission();
        let via = match self.selected {
            Item::Obstacle(i) if i < m.obstacles.len() => {
                let here = m.prism(&m.obstacles[i]);
                let band = m.bounds.z;
                let nearest = m
                    .obstacles
                    .iter()
                    .enumerate()
                    .filter(|(j, o)| *j != i && o.within(band))
                    .map(|(_, o)| {
                        let (p, q) = crate::base::shape::nearest_points(
                            &*here.outline,
                            &*m.prism(o).outline,
                        );
                        (o.name.clone(), (q - p).norm())
                    })
                    .min_by(|a, b| a.1.total_cmp(&b.1));
                let Some((other, _)) = nearest else {
                    status.error("a gate needs a second obstacle in the altitude band");
                    return;
                };
                crate::mission::Via {
                    between: Some([m.obstacles[i].name.clone(), other]),
                    point: None,
                    radius: None,
                }
            }
            _ => {
                let z = m.route.start.z.clamp(m.bounds.z[0], m.bounds.z[1]);
                crate::mission::Via {
                    between: None,
                    point: Some(nalgebra::Point3::new(
                        mission::round_mm(at.x),
                        mission::round_mm(at.y),
                        z,
                    )),
                    radius: None,
                }
            }
        };
        let label = via.label();
        self.edit(status, |m| m.route.via.push(via));
        let k = self.mission().route.via.len() - 1;
        self.select(Item::Via(k));
        status.say(format!(
            "route via {}: {label}: the route must take it, after the vias before it (u undoes)",
            k + 1
        ));
    }

    fn toggle_inspect(&mut self, status: &mut StatusLine) {
        if let Item::Obstacle(i) = self.selected
            && let Some(o) = self.mission().obstacles.get(i)
        {
            let inspect = !o.inspect;
            let name = o.name.clone();
            self.edit(status, |m| m.obstacles[i].inspect = inspect);
            status.say(if inspect {
                format!("inspecting '{name}': the plan flies a pass along it (eq. 8)")
            } else {
                format!("'{name}' is no longer inspected")
            });
        } else {
            status.say("select an obstacle (n/p or click) to inspect it");
        }
    }

    /// One more UAV: a preset grows as itself (a diamond of 5 is a diamond
    /// of 6), at a spacing valid for the mission; a custom shape gets one
    /// behind its rearmost slot.
    fn add_slot(&mut self, status: &mut StatusLine) {
        let n = self.mission().formation.slots.len() + 1;
        let mut trial = self.mission().clone();
        let said = match Preset::detect(&trial.formation.slots) {
            Some((preset, _)) if n > 2 => match mission::reshape(&mut trial, preset, n, None) {
                Ok(spacing) => format!(
                    "formation: {} of {n}, {} m apart",
                    preset.name(),
                    fields::fmt_num(spacing)
                ),
                Err(e) => {
                    status.error(e);
                    return;
                }
            },
            _ => {
                let spacing = mission::spacing_of(&trial);
                trial.formation.slots = mission::resize_custom(&trial.formation.slots, n, spacing);
                format!("slot {n} added behind the others")
            }
        };
        self.edit(status, |m| *m = trial);
        self.select(Item::Slot(n - 1));
        status.say(said);
    }

    /// The next preset for this many UAVs that draws a new shape and fits
    /// the mission (r_Q, shrink, d_com); those that do not fit are named.
    fn cycle_preset(&mut self, status: &mut StatusLine) {
        let n = self.mission().formation.slots.len().max(1);
        let scale = mission::smallest_scale(&self.mission().reconfiguration);
        let formation = &self.mission().formation;
        let (fit, misfits): (Vec<Preset>, Vec<Preset>) = Preset::distinct(n)
            .into_iter()
            .partition(|p| p.spacing_range(n, formation, scale).is_some());
        let current = self.current_preset().unwrap_or(self.preset);
        let after = Preset::ALL.iter().position(|p| *p == current).unwrap_or(0);
        let next = (1..=Preset::ALL.len())
            .map(|k| Preset::ALL[(after + k) % Preset::ALL.len()])
            .find(|p| fit.contains(p));
        let Some(next) = next else {
            let mut trial = self.mission().clone();
            let why = mission::reshape(&mut trial, current, n, None)
                .err()
                .unwrap_or_default();
            status.error(format!("no preset of {n} fits this mission: {why}"));
            return;
        };
        self.preset = next;
        let mut trial = self.mission().clone();
        match mission::reshape(&mut trial, next, n, None) {
            Ok(spacing) => {
                self.edit(status, |m| *m = trial);
                let skipped = if misfits.is_empty() {
                    String::new()
                } else {
                    let names: Vec<&str> = misfits.iter().map(|p| p.name()).collect();
                    format!(" ({} of {n} would not fit d_com)", names.join(", "))
                };
                status.say(format!(
                    "formation: {} of {n}, {} m apart{skipped}",
                    next.name(),
                    fields::fmt_num(spacing)
                ));
            }
            Err(e) => status.error(e),
        }
    }

    /// The next shape for the selected IWP, said on the status line with
    /// what it makes of the route: a choice in the file is a crossing the
    /// route must make (`route::find`'s requested stops).
    fn cycle_shape(&mut self, status: &mut StatusLine) {
        if let Item::Waypoint(between) = &self.selected {
            let (item, between) = (self.selected.clone(), between.clone());
            self.edit(status, |m| {
                if let Ok(choice) = fields::waypoint_choice(m, &item) {
                    choice.shape = fields::next_shape(choice.shape);
                }
            });
            status.say(self.iwp_said(&between));
        } else {
            // Say what `s` needs rather than do nothing.
            let iwps = self.iwps.len();
            status.error(if iwps == 0 {
                "s changes an IWP's shape: this mission has no IWP".to_owned()
            } else {
                format!(
                    "s changes an IWP's shape: select one of the {iwps} IWP row(s) \
                     first (2 formation editor, then n)"
                )
            });
        }
    }

    /// What the IWP between `between` is now, for the status line: its
    /// shape (chosen, or auto and the one that fits), and whether the route
    /// must cross it: an IWP with a choice in the file (`s` and `Space`
    /// write one) is a stop of the route, as an inspection is.
    fn iwp_said(&self, between: &[String; 2]) -> String {
        let [a, b] = between;
        let choice = self.mission().reconfiguration.choice(a, b);
        let Some(iwp) = self.iwps.iter().find(|w| w.between == *between) else {
            // Not an IWP of the mission as it is (a choice naming a gap
            // that is not one): the choice alone.
            let shape = choice.map_or("auto", |c| fields::shape_name(c.shape));
            return format!("{shape} chosen for '{a}' ↔ '{b}', which is no IWP now");
        };
        let shape = match choice.map(|c| c.shape) {
            None | Some(ShapeChoice::Auto) => format!("auto → {}", iwp.shape_name()),
            Some(chosen) => format!("{} (chosen)", fields::shape_name(chosen)),
        };
        if let Some(why) = &iwp.unusable {
            return format!("{shape}: no shape passes between '{a}' and '{b}': {why}");
        }
        match (iwp.enabled, choice.is_some()) {
            (false, _) => format!(
                "IWP off ({shape}): the route need not cross between '{a}' and '{b}' (Space: on)"
            ),
            (true, true) => format!("{shape}: the route must cross between '{a}' and '{b}'"),
            (true, false) => format!("{shape}: the route may cross between '{a}' and '{b}' or not"),
        }
    }

    /// Undo (`back`) or redo.
    fn step_history(&mut self, back: bool, status: &mut StatusLine) {
        self.editing = None;
        self.drag = None;
        let (done, said) = if back {
            (self.doc.undo(), ["undone", "nothing to undo"])
        } else {
            (self.doc.redo(), ["redone", "nothing to redo"])
        };
        if done {
            self.refresh();
            status.say(said[0]);
        } else {
            status.say(said[1]);
        }
    }

    fn drag_start(&mut self, item: Item, at: Point2<f64>) {
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

    fn drag_to(&mut self, at: Point2<f64>, step: f64) {
        if let Some(drag) = self.drag.clone() {
            // Dragged positions snap to the nudge step, as the keys move.
            let snap = |v: f64| (v / step).round() * step;
            let p = at + drag.grab;
            let p = Point2::new(snap(p.x), snap(p.y));
            self.doc.gesture_edit(|m| set_position(m, &drag.item, p));
        }
    }

    fn drag_end(&mut self) {
        if self.drag.take().is_some() {
            self.doc.end_gesture();
            self.refresh();
        }
    }

    /// The preset the slots are now (after any undo), if they are one.
    pub fn current_preset(&self) -> Option<Preset> {
        Preset::detect(&self.mission().formation.slots).map(|(p, _)| p)
    }

    fn nudge(&mut self, dx: f64, dy: f64, s: f64, status: &mut StatusLine) {
        let item = self.selected.clone();
        match &item {
            Item::Obstacle(_)
            | Item::Vertex(_, _)
            | Item::Start
            | Item::Goal
            | Item::Via(_)
            | Item::Point(_) => {
                if let Some(p) = self.position_of(&item) {
                    let to = p + Vector2::new(dx * s, dy * s);
                    self.edit(status, |m| set_position(m, &item, to));
                }
            }
            Item::Slot(i) => {
                let i = *i;
                // Formation frame on screen: forward is up, left is left.
                self.edit(status, |m| {
                    if let Some(slot) = m.formation.slots.get_mut(i) {
                        slot.x = mission::round_mm(slot.x + dy * s);
                        slot.y = mission::round_mm(slot.y - dx * s);
                    }
                });
            }
            _ => {
                status.say("select an obstacle, a vertex, the start, the goal or a slot to move it")
            }
        }
    }

    /// Where a movable item is, in its pane's plane (map: x, y ENU; formation:
    /// forward, left).
    fn position_of(&self, item: &Item) -> Option<Point2<f64>> {
        let m = self.mission();
        match item {
            Item::Obstacle(i) => m.obstacles.get(*i).map(|o| o.center),
            Item::Vertex(i, v) => m.obstacles.get(*i)?.footprint.get(*v).copied(),
            Item::Start => Some(m.route.start.xy()),
            Item::Goal => Some(m.route.goal.xy()),
            Item::Slot(i) => m.formation.slots.get(*i).map(|s| Point2::new(s.x, s.y)),
            Item::Point(p) => p.centre(m),
            // A via point moves; a gate is where its obstacles are.
            Item::Via(i) => m.route.via.get(*i)?.point.map(|p| p.xy()),
            _ => None,
        }
    }

    fn delete(&mut self, status: &mut StatusLine) {
        match self.selected.clone() {
            Item::Obstacle(i) => {
                let name = self.mission().obstacles.get(i).map(|o| o.name.clone());
                self.edit(status, |m| {
                    if i < m.obstacles.len() {
                        m.obstacles.remove(i);
                    }
                });
                if let Some(name) = name {
                    status.say(format!("deleted '{name}' (u to undo)"));
                }
            }
            Item::Vertex(i, v) => {
                let n = self
                    .mission()
                    .obstacles
                    .get(i)
                    .map_or(0, |o| o.footprint.len());
                if n <= 3 {
                    status.error("a footprint needs at least three vertices (c, then Del deletes the obstacle)");
                    return;
                }
                self.edit(status, |m| {
                    let o = &mut m.obstacles[i];
                    if v < o.footprint.len() {
                        o.footprint.remove(v);
                        o.settle();
                    }
                });
                self.select(Item::Vertex(i, v.min(n - 2)));
                status.say(format!("vertex {} deleted (u to undo)", v + 1));
            }
            Item::Slot(i) => {
                if self.mission().formation.slots.len() <= 1 {
                    status.error("a formation needs at least one slot");
                    return;
                }
                self.edit(status, |m| {
                    if i < m.formation.slots.len() {
                        m.formation.slots.remove(i);
                    }
                });
            }
            Item::Point(p) => {
                if let Some(k) = p.kind() {
                    self.edit(status, |m| (k.remove)(m, p.index));
                    status.say(format!("{} deleted (u to undo)", k.noun.to_lowercase()));
                }
            }
            Item::Via(i) => {
                self.edit(status, |m| {
                    if i < m.route.via.len() {
                        m.route.via.remove(i);
                    }
                });
                let left = self.mission().route.via.len();
                self.select(if left > 0 {
                    Item::Via(i.min(left - 1))
                } else {
                    Item::Goal
                });
                status.say(format!("route via {} deleted (u to undo)", i + 1));
            }
            Item::Waypoint(between) => {
                self.edit(status, |m| {
                    m.reconfiguration
                        .waypoints
                        .retain(|w| !w.is_between(&between[0], &between[1]))
                });
                let [a, b] = &between;
                status.say(format!(
                    "IWP back to the mission's default shape: the route may cross between '{a}' and '{b}' or not"
                ));
            }
            _ => status.say("only obstacles, vertices, slots and IWP choices can be deleted"),
        }
    }

    /// Starts typing into the field under the cursor (with its value, or
    /// `first` alone); false when there is no field.
    fn start_editing(&mut self, first: Option<char>) -> bool {
        let fields = self.fields();
        let Some(f) = fields.get(self.field) else {
            return false;
        };
        let buffer = match first {
            Some(c) => c.to_string(),
            None => f.value().to_owned(),
        };
        self.editing = Some(Editing {
            buffer,
            problem: None,
        });
        self.check_editing();
        true
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
            // What the value would cause on this field, or on the array
            // it is an element of (x max of an inverted x range).
            Ok(()) => crate::outcome::diagnose::diagnose(&trial)
                .into_iter()
                .filter(|d| {
                    fields::place(&self.selected, &trial, &fields, &d.path)
                        .is_some_and(|(at, _)| at.covers(self.field))
                })
                .min_by_key(|d| d.severity)
                .map(|d| (d.severity, d.message)),
        };
        if let Some(e) = &mut self.editing {
            e.problem = problem;
        }
    }

    fn commit_edit(&mut self, status: &mut StatusLine) {
        let Some(editing) = self.editing.take() else {
            return;
        };
        let fields = self.fields();
        let Some(field) = fields.get(self.field) else {
            return;
        };
        // Enter applies and stays on the field: ↓ goes to the next one (a
        // move on Enter as well made the next ↓ skip a field).
        if editing.buffer.trim() == field.value() {
            // Nothing typed: no change, no undo step (and no rounding).
            return;
        }
        let mut trial = self.mission().clone();
        match field.set(&mut trial, &self.selected, &editing.buffer) {
            Ok(()) => {
                self.edit(status, |m| *m = trial);
                status.say(format!("{} = {}", field.label(), editing.buffer.trim()));
            }
            Err(e) => {
                // Keep the text so it can be corrected.
                status.error(format!("{}: {e}", field.label()));
                self.editing = Some(Editing {
                    problem: Some((Severity::Error, e)),
                    ..editing
                });
            }
        }
    }
}

/// The IWPs (eq. 9) of a mission whose only errors, if any, are in IWP
/// choices: those choices are left out, so the map still marks every IWP
/// while the user fixes the choice. Any other error: none.
fn iwps_despite_choices(m: &Mission, revision: &crate::pipelines::Revision) -> Vec<Iwp> {
    let diagnostics = revision.diagnostics();
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
        // Found with the revision's findings already.
        return match crate::pipelines::theta_pso::face::prepared_iwps(revision) {
            Some(iwps) => iwps.clone(),
            None => find_iwps(m),
        };
    }
    let mut clean = m.clone();
    let mut k = 0;
    clean.reconfiguration.waypoints.retain(|_| {
        k += 1;
        !bad.contains(&(k - 1))
    });
    find_iwps(&clean)
}

/// Moves a movable item to `p`, to the millimetre (steps of 0.1 m add up
/// to 0.30000000000000004 otherwise, and files would say so).
fn set_position(m: &mut Mission, item: &Item, p: Point2<f64>) {
    let p = p.map(mission::round_mm);
    match item {
        Item::Obstacle(i) => {
            if let Some(o) = m.obstacles.get_mut(*i) {
                o.move_to(p);
            }
        }
        Item::Vertex(i, v) => {
            if let Some(o) = m.obstacles.get_mut(*i)
                && let Some(q) = o.footprint.get_mut(*v)
            {
                *q = p;
                o.settle();
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
        Item::Point(q) => {
            if let Some(k) = q.kind() {
                (k.move_to)(m, q.index, p);
            }
        }
        Item::Via(i) => {
            if let Some(q) = m.route.via.get_mut(*i).and_then(|v| v.point.as_mut()) {
                q.x = p.x;
                q.y = p.y;
            }
        }
        _ => {}
    }
}

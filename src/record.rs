//! Rerun recordings: the mission scene, live θ-PSO progress and the results,
//! saved to `.rrd` and/or streamed to a viewer.
//!
//! One file for the sinks, the worker and the three pipelines' layouts, so
//! the layout documented in `docs/rerun.md` reads in one place; over 700
//! lines for that reason (the layouts could move to `record/layout.rs`).
//!
//! Layout (see `docs/rerun.md`): `world` is right-handed, Z up, metres, with
//! `world/bounds`, `world/obstacles`, `world/route`, `world/iwps` static.
//! θ-PSO logs under `theta_pso/…`: the best path of each iteration and the
//! cost terms on the `iteration` timeline, the UAVs on `sim_time`.
//!
//! Nothing here runs on the pipeline's thread but the cheap conversion of an
//! event into a message: a worker thread owns the `RecordingStream` and is fed
//! through a bounded queue that drops the oldest message when full, so a slow
//! or vanished viewer never blocks planning (or, later, the UI).

use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, Sender, TrySendError};
use nalgebra::Point3;
use rerun::sink::{FileSink, GrpcSink, LogSink};
use rerun::{RecordingStream, RecordingStreamBuilder};

use crate::flatlo::FlatloOutcome;
use crate::fleet::FleetOutcome;
use crate::mission::{Mission, to_toml_string};
use crate::outcome::Outcome;
use crate::pipeline::{CostTerms, Event, Level, Observer};
use crate::planner::{ThetaPsoOutcome, find_iwps};

/// The viewer's standard local address.
pub const DEFAULT_VIEWER_URL: &str = "rerun+http://127.0.0.1:9876/proxy";

/// Messages in flight before the oldest are dropped.
const QUEUE_CAPACITY: usize = 4096;

/// Where a recording goes. Any combination; none at all records nothing.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Sinks {
    /// Save to this `.rrd` file.
    pub rrd: Option<PathBuf>,
    /// Stream to a running viewer at this URL.
    pub connect: Option<String>,
    /// Start a local viewer (`rerun` on PATH) and stream to it.
    pub spawn: bool,
}

impl Sinks {
    pub fn is_empty(&self) -> bool {
        self.rrd.is_none() && self.connect.is_none() && !self.spawn
    }
}

/// Errors that stop a recording from starting (a viewer that cannot be
/// reached is only a warning).
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    #[error("cannot create the recording file {path}: {message}")]
    File { path: String, message: String },
    #[error("'{url}' is not a Rerun viewer URL (expected e.g. {DEFAULT_VIEWER_URL}): {message}")]
    Url { url: String, message: String },
    #[error("cannot start the recording: {0}")]
    Stream(String),
}

/// What the worker is asked to log.
enum Message {
    Scene(Box<Mission>),
    Iteration {
        iteration: usize,
        cost: CostTerms,
        path: Vec<[f32; 3]>,
    },
    Log(Level, String),
    Outcome(Box<Outcome>),
}

/// A recording in progress. `finish` (or drop) flushes it and closes the file.
pub struct Recorder {
    queue: Sender<Message>,
    /// Kept to drop the oldest message when the queue is full.
    oldest: Receiver<Message>,
    worker: Option<JoinHandle<()>>,
    dropped: usize,
    file: Option<PathBuf>,
}

/// What a finished recording left behind.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finished {
    /// The `.rrd` written, with its size in bytes.
    pub file: Option<(PathBuf, u64)>,
    /// Messages dropped because the queue was full.
    pub dropped: usize,
}

impl Recorder {
    /// Opens the sinks and starts the worker. `None` when `sinks` is empty or
    /// every viewer sink failed; `warnings` gets one line per viewer that
    /// could not be reached or started.
    pub fn start(
        name: &str,
        sinks: &Sinks,
        warnings: &mut Vec<String>,
    ) -> Result<Option<Recorder>, RecordError> {
        let mut boxes: Vec<Box<dyn LogSink>> = Vec::new();
        if let Some(path) = &sinks.rrd {
            check_rrd_path(path).map_err(|message| RecordError::File {
                path: path.display().to_string(),
                message,
            })?;
            let sink = FileSink::new(path).map_err(|e| RecordError::File {
                path: path.display().to_string(),
                message: e.to_string(),
            })?;
            boxes.push(Box::new(sink));
        }
        let mut urls = Vec::new();
        if sinks.spawn {
            match spawn_viewer() {
                Ok(url) => urls.push(url),
                Err(w) => warnings.push(w),
            }
        }
        if let Some(url) = &sinks.connect {
            urls.push(url.clone());
        }
        for url in urls {
            let uri: rerun::external::re_uri::ProxyUri =
                url.parse().map_err(|e| RecordError::Url {
                    url: url.clone(),
                    message: format!("{e}"),
                })?;
            // Probe first: the SDK accepts an unreachable address silently and
            // would buffer everything for a viewer that never comes.
            if viewer_listening(&uri.origin.host.to_string(), uri.origin.port) {
                boxes.push(Box::new(GrpcSink::new(uri)));
            } else {
                warnings.push(format!(
                    "no Rerun viewer answers at {url}; continuing without it \
                     (start one with `rerun`, or save with --rrd)"
                ));
            }
        }
        if boxes.is_empty() {
            return Ok(None);
        }
        let stream = RecordingStreamBuilder::new("skyform")
            .set_sinks(boxes)
            .map_err(|e| RecordError::Stream(e.to_string()))?;
        let _ = stream.send_recording_name(name);
        // A layout that shows the plan large: not essential, so a failure is ignored.
        let _ = layout(Layout::ThetaPso)
            .send(&stream, rerun::blueprint::BlueprintActivation::default());
        let (queue, inbox) = crossbeam_channel::bounded(QUEUE_CAPACITY);
        let oldest = inbox.clone();
        let worker = std::thread::Builder::new()
            .name("rerun-recorder".into())
            .spawn(move || run_worker(stream, inbox))
            .map_err(|e| RecordError::Stream(e.to_string()))?;
        Ok(Some(Recorder {
            queue,
            oldest,
            worker: Some(worker),
            dropped: 0,
            file: sinks.rrd.clone(),
        }))
    }

    fn send(&mut self, mut message: Message) {
        loop {
            match self.queue.try_send(message) {
                Ok(()) => return,
                Err(TrySendError::Full(m)) => {
                    if self.oldest.try_recv().is_ok() {
                        self.dropped += 1;
                    }
                    message = m;
                }
                Err(TrySendError::Disconnected(_)) => return,
            }
        }
    }

    /// Logs the mission as static data.
    pub fn log_mission(&mut self, mission: &Mission) {
        self.send(Message::Scene(Box::new(mission.clone())));
    }

    /// Logs a pipeline's result in its layout.
    pub fn log_outcome(&mut self, outcome: &Outcome) {
        self.send(Message::Outcome(Box::new(outcome.clone())));
    }

    /// Flushes everything and closes the sinks; the `.rrd` is complete after this.
    pub fn finish(mut self) -> Finished {
        self.close()
    }

    fn close(&mut self) -> Finished {
        // Disconnecting the queue ends the worker's loop once it has drained it.
        let (dead, _) = crossbeam_channel::bounded(0);
        drop(std::mem::replace(&mut self.queue, dead));
        if let Some(worker) = self.worker.take() {
            let _ = worker.join();
        }
        let file = self.file.take().map(|p| {
            let size = std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0);
            (p, size)
        });
        Finished {
            file,
            dropped: self.dropped,
        }
    }
}

impl Drop for Recorder {
    fn drop(&mut self) {
        if self.worker.is_some() {
            self.close();
        }
    }
}

/// The recorder as a pipeline observer: events become queued messages.
impl Observer for Recorder {
    fn on_event(&mut self, event: Event<'_>) {
        match event {
            Event::PathIteration {
                iteration,
                cost,
                path,
            } => self.send(Message::Iteration {
                iteration,
                cost: *cost,
                path: path.iter().map(f32x3).collect(),
            }),
            Event::Log(level, text) => self.send(Message::Log(level, text.to_owned())),
            Event::Stage(_) | Event::Progress(_) => {}
        }
    }
}

fn f32x3(p: &Point3<f64>) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}

/// Why streaming to a viewer would not work now, if it would not: nothing
/// listens at the default port (`connect`), or no `rerun` on PATH
/// (`spawn`). A quick check for the designer's status bar.
pub fn viewer_problem(spawn: bool) -> Option<String> {
    let port = rerun::DEFAULT_SERVER_PORT;
    if viewer_listening("127.0.0.1", port) {
        return None;
    }
    if !spawn {
        return Some(format!(
            "no Rerun viewer listens on port {port}: start one with `rerun --port {port}` \
             (runs go on without it)"
        ));
    }
    let on_path = std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join("rerun").is_file()));
    (!on_path).then(|| {
        "`rerun` is not on PATH: install it with `pip install rerun-sdk==0.36.3` \
         (runs go on without it)"
            .to_owned()
    })
}

/// Is something listening at host:port? A short TCP connect, nothing more.
fn viewer_listening(host: &str, port: u16) -> bool {
    let addrs: Vec<SocketAddr> = (host, port)
        .to_socket_addrs()
        .map(|a| a.collect())
        .unwrap_or_default();
    addrs
        .iter()
        .any(|a| TcpStream::connect_timeout(a, Duration::from_millis(300)).is_ok())
}

/// Starts `rerun` with its output silenced (it would scribble over a TUI) and
/// waits for it to listen. Returns the URL to connect to, or a warning.
fn spawn_viewer() -> Result<String, String> {
    let port = rerun::DEFAULT_SERVER_PORT;
    if viewer_listening("127.0.0.1", port) {
        return Ok(DEFAULT_VIEWER_URL.to_owned());
    }
    let child = Command::new("rerun")
        .arg("--port")
        .arg(port.to_string())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn();
    let mut child = match child {
        Ok(c) => c,
        Err(e) => {
            return Err(format!(
                "cannot start the Rerun viewer ({e}); install it with \
                 `pip install rerun-sdk==0.36.3`. Continuing without it."
            ));
        }
    };
    let deadline = Instant::now() + Duration::from_secs(10);
    while Instant::now() < deadline {
        if viewer_listening("127.0.0.1", port) {
            return Ok(DEFAULT_VIEWER_URL.to_owned());
        }
        if let Ok(Some(status)) = child.try_wait() {
            return Err(format!(
                "the Rerun viewer exited at once ({status}; is there a display?); \
                 continuing without it"
            ));
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    Err("the Rerun viewer started but did not listen within 10 s; continuing without it".into())
}

/// The worker: takes messages until the queue is closed, batching the
/// θ-PSO iterations that arrive together into one `send_columns` per series.
fn run_worker(stream: RecordingStream, inbox: Receiver<Message>) {
    let mut pending: Vec<(usize, CostTerms, Vec<[f32; 3]>)> = Vec::new();
    // The mission of the scene, for what an outcome is measured against.
    let mut scene: Option<Box<Mission>> = None;
    while let Ok(first) = inbox.recv() {
        let mut batch = vec![first];
        batch.extend(inbox.try_iter());
        for message in batch {
            match message {
                Message::Iteration {
                    iteration,
                    cost,
                    path,
                } => pending.push((iteration, cost, path)),
                other => {
                    flush_iterations(&stream, &mut pending);
                    if let Message::Scene(m) = &other {
                        scene = Some(m.clone());
                    }
                    log_message(&stream, other, scene.as_deref());
                }
            }
        }
        flush_iterations(&stream, &mut pending);
    }
    let _ = stream.flush_with_timeout(Duration::from_secs(10));
    drop(stream);
}

fn log_message(stream: &RecordingStream, message: Message, scene: Option<&Mission>) {
    let result = match message {
        Message::Scene(mission) => log_scene(stream, &mission),
        Message::Outcome(outcome) => match *outcome {
            Outcome::ThetaPso(o) => log_theta_pso(stream, &o, scene),
            Outcome::Flatlo(o) => {
                let _ = layout(Layout::Flatlo)
                    .send(stream, rerun::blueprint::BlueprintActivation::default());
                log_flatlo(stream, &o)
            }
            Outcome::Fleet(o) => {
                let _ = layout(Layout::Fleet)
                    .send(stream, rerun::blueprint::BlueprintActivation::default());
                log_fleet(stream, &o)
            }
        },
        Message::Log(level, text) => {
            let level = match level {
                Level::Info => rerun::TextLogLevel::INFO,
                Level::Warn => rerun::TextLogLevel::WARN,
            };
            stream.log(
                "theta_pso/log",
                &rerun::TextLog::new(text).with_level(level),
            )
        }
        Message::Iteration { .. } => Ok(()),
    };
    // A logging error (a sink gone) must not stop the run; the recording is
    // best effort from here on.
    let _ = result;
}

/// Picks one term out of the cost breakdown.
type CostTerm = fn(&CostTerms) -> f64;

/// One `send_columns` per series for all iterations gathered so far.
fn flush_iterations(
    stream: &RecordingStream,
    pending: &mut Vec<(usize, CostTerms, Vec<[f32; 3]>)>,
) {
    if pending.is_empty() {
        return;
    }
    let iterations =
        rerun::TimeColumn::new_sequence("iteration", pending.iter().map(|(i, _, _)| *i as i64));
    let series: [(&str, CostTerm); 5] = [
        ("theta_pso/cost/J_total", |c| c.total),
        ("theta_pso/cost/J1_length", |c| c.length),
        ("theta_pso/cost/J2_obstacle", |c| c.obstacle),
        ("theta_pso/cost/J3_altitude", |c| c.altitude),
        ("theta_pso/cost/JR_waypoints", |c| c.waypoints),
    ];
    for (path, term) in series {
        let values: Vec<f64> = pending.iter().map(|(_, c, _)| term(c)).collect();
        let _ = log_series(stream, path, &iterations, values);
    }
    let strips: Vec<Vec<[f32; 3]>> = pending.drain(..).map(|(_, _, p)| p).collect();
    if let Ok(columns) = rerun::LineStrips3D::update_fields()
        .with_strips(strips)
        .columns_of_unit_batches()
    {
        let _ = stream.send_columns("theta_pso/best_path", [iterations], columns);
    }
}

/// Which pipeline's plots the viewer layout puts beside the scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Layout {
    ThetaPso,
    Flatlo,
    Fleet,
}

/// The viewer layout: the 3D scene large on the left; on the right the
/// pipeline's series (θ-PSO cost terms; FLATLO airspeeds and load factors;
/// the fleet's inter-agent distances, Fig. 13), its events, and the mission
/// file. A recording starts with the θ-PSO layout; a FLATLO or fleet result
/// sends its own, which the viewer then shows.
fn layout(kind: Layout) -> rerun::blueprint::Blueprint {
    use rerun::blueprint::{
        Blueprint, BlueprintPanel, ContainerLike, Horizontal, SelectionPanel, Spatial3DView, Tabs,
        TextDocumentView, TextLogView, TimePanel, TimeSeriesView, Vertical,
    };
    let (series, events): (Vec<ContainerLike>, &str) = match kind {
        // The clearance plays with the flight on `sim_time`, the timeline
        // the viewer opens on; the cost is on `iteration`, in the tab behind.
        Layout::ThetaPso => (
            vec![
                Tabs::new([
                    TimeSeriesView::new("clearance to obstacles, m")
                        .with_origin("/theta_pso/clearance")
                        .into(),
                    TimeSeriesView::new("θ-PSO cost (timeline: iteration)")
                        .with_origin("/theta_pso/cost")
                        .into(),
                ])
                .into(),
            ],
            "/theta_pso",
        ),
        Layout::Flatlo => (
            vec![
                TimeSeriesView::new("airspeed, m/s")
                    .with_origin("/flatlo/airspeed")
                    .into(),
                TimeSeriesView::new("load factor")
                    .with_origin("/flatlo/load_factor")
                    .into(),
            ],
            "/flatlo",
        ),
        Layout::Fleet => (
            vec![
                TimeSeriesView::new("inter-agent distances, m (Fig. 13)")
                    .with_origin("/fleet/distances")
                    .into(),
            ],
            "/fleet",
        ),
    };
    let mut column = series;
    column.push(TextLogView::new("events").with_origin(events).into());
    column.push(
        TextDocumentView::new("mission")
            .with_origin("/mission")
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

/// The mission as static data.
fn log_scene(stream: &RecordingStream, m: &Mission) -> rerun::RecordingStreamResult<()> {
    stream.log_static("world", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
    let b = &m.bounds;
    stream.log_static(
        "world/bounds",
        &rerun::Boxes3D::from_mins_and_sizes(
            [[b.x[0] as f32, b.y[0] as f32, b.z[0] as f32]],
            [[
                (b.x[1] - b.x[0]) as f32,
                (b.y[1] - b.y[0]) as f32,
                (b.z[1] - b.z[0]) as f32,
            ]],
        )
        .with_labels(["altitude band"]),
    )?;
    if !m.obstacles.is_empty() {
        let o = &m.obstacles;
        stream.log_static(
            "world/obstacles",
            &rerun::Cylinders3D::from_lengths_and_radii(
                o.iter().map(|o| o.height as f32),
                o.iter().map(|o| o.radius as f32),
            )
            .with_centers(o.iter().map(|o| {
                [
                    o.center.x as f32,
                    o.center.y as f32,
                    (o.height / 2.0) as f32,
                ]
            }))
            .with_labels(o.iter().map(|o| o.name.clone()))
            .with_colors(o.iter().map(|o| {
                if o.inspect {
                    rerun::Color::from_rgb(200, 90, 200)
                } else {
                    rerun::Color::from_rgb(150, 150, 160)
                }
            })),
        )?;
        // Inspected surfaces (eq. 8): the stand-off band's outer shell,
        // translucent, over the altitude band.
        let inspected: Vec<_> = o.iter().filter(|o| o.inspect).collect();
        if !inspected.is_empty() {
            let band_height = (m.bounds.z[1] - m.bounds.z[0]) as f32;
            stream.log_static(
                "world/inspection",
                &rerun::Cylinders3D::from_lengths_and_radii(
                    inspected.iter().map(|_| band_height),
                    inspected
                        .iter()
                        .map(|o| (o.radius + o.stand_off_band(&m.formation)[1]) as f32),
                )
                .with_centers(inspected.iter().map(|o| {
                    [
                        o.center.x as f32,
                        o.center.y as f32,
                        ((m.bounds.z[0] + m.bounds.z[1]) / 2.0) as f32,
                    ]
                }))
                .with_labels(inspected.iter().map(|o| {
                    let [lo, hi] = o.stand_off_band(&m.formation);
                    format!("inspect {}: {lo}-{hi} m", o.name)
                }))
                .with_colors(
                    inspected
                        .iter()
                        .map(|_| rerun::Color::from_unmultiplied_rgba(200, 90, 200, 40)),
                ),
            )?;
        }
    }
    stream.log_static(
        "world/route",
        &rerun::Points3D::new([f32x3(&m.route.start), f32x3(&m.route.goal)])
            .with_labels(["start", "goal"])
            .with_radii([0.6f32, 0.6])
            .with_colors([
                rerun::Color::from_rgb(60, 200, 60),
                rerun::Color::from_rgb(220, 60, 60),
            ]),
    )?;
    if let (Some(terrain), Some(map)) = (&m.terrain, m.height_map()) {
        log_terrain(stream, map, terrain.lookup)?;
    }
    let iwps = find_iwps(m);
    if !iwps.is_empty() {
        let z = ((m.bounds.z[0] + m.bounds.z[1]) / 2.0) as f32;
        stream.log_static(
            "world/iwps",
            &rerun::Points3D::new(
                iwps.iter()
                    .map(|i| [i.position.x as f32, i.position.y as f32, z]),
            )
            .with_labels(iwps.iter().map(|i| {
                let state = if i.enabled { "" } else { " (disabled)" };
                format!("IWP {} | {}{state}", i.between[0], i.between[1])
            }))
            .with_radii(iwps.iter().map(|_| 0.4f32))
            .with_colors(iwps.iter().map(|i| {
                if i.enabled {
                    rerun::Color::from_rgb(250, 200, 0)
                } else {
                    rerun::Color::from_rgb(120, 120, 120)
                }
            })),
        )?;
    }
    let toml = to_toml_string(m).unwrap_or_default();
    stream.log_static(
        "mission",
        &rerun::TextDocument::from_markdown(format!(
            "# {}\n\n{}\n\nskyform {}\n\n```toml\n{toml}\n```\n",
            m.name,
            m.description,
            env!("CARGO_PKG_VERSION")
        )),
    )?;
    Ok(())
}

/// The mission's height map as a mesh of at most 200 × 200 points, coloured
/// by height (`terrain::height_colour`: the hues of the designer's map, brighter).
fn log_terrain(
    stream: &RecordingStream,
    map: &crate::terrain::HeightMap,
    lookup: crate::terrain::Lookup,
) -> rerun::RecordingStreamResult<()> {
    let grid = crate::terrain::Grid::of(map, lookup, 200);
    let [low, high] = map.range;
    let span = f64::from(high - low).max(1e-9);
    stream.log_static(
        "world/terrain",
        &rerun::Mesh3D::new(
            grid.points
                .iter()
                .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32]),
        )
        .with_triangle_indices(grid.triangles())
        .with_vertex_colors(grid.points.iter().map(|p| {
            let [r, g, b] = crate::terrain::height_colour((p[2] - f64::from(low)) / span);
            rerun::Color::from_rgb(r, g, b)
        })),
    )
}

/// Each UAV's clearance over `sim_time`: the distance from its sphere of
/// radius r_Q to the nearest obstacle (terrain-raised), 0 = touching. The
/// plot beside the scene on the timeline the flight plays on.
fn log_clearances(
    stream: &RecordingStream,
    o: &ThetaPsoOutcome,
    m: &Mission,
) -> rerun::RecordingStreamResult<()> {
    let cylinders: Vec<_> = m.obstacles.iter().map(|ob| m.cylinder(ob)).collect();
    if cylinders.is_empty() {
        return Ok(());
    }
    for t in &o.trajectories {
        let entity = format!("theta_pso/clearance/uav_{}", t.uav + 1);
        stream.log_static(
            entity.as_str(),
            &rerun::SeriesLines::new()
                .with_colors([uav_color(t.uav)])
                .with_names([format!("UAV {}", t.uav + 1)]),
        )?;
        let times = rerun::TimeColumn::new_duration_secs("sim_time", t.samples.iter().map(|s| s.t));
        let values = t
            .samples
            .iter()
            .map(|s| {
                cylinders
                    .iter()
                    .map(|c| c.clearance(&s.position))
                    .fold(f64::INFINITY, f64::min)
                    - m.formation.uav_radius
            })
            .collect();
        log_series(stream, &entity, &times, values)?;
    }
    Ok(())
}

/// Vehicle `n`'s colour, the same as on the designer's map.
fn uav_color(n: usize) -> rerun::Color {
    let [r, g, b] = crate::tracks::vehicle_color(n);
    rerun::Color::from_rgb(r, g, b)
}

/// A point that moves on `sim_time`: its style (colour, radius, label)
/// logged once, its positions as one `send_columns`.
fn log_moving_point(
    stream: &RecordingStream,
    entity: &str,
    times: &rerun::TimeColumn,
    style: rerun::Points3D,
    positions: Vec<[f32; 3]>,
) -> rerun::RecordingStreamResult<()> {
    stream.log_static(entity, &style)?;
    stream.send_columns(
        entity,
        [times.clone()],
        rerun::Points3D::update_fields()
            .with_positions(positions)
            .columns_of_unit_batches()?,
    )
}

/// A scalar series over `times`, as one `send_columns`.
fn log_series(
    stream: &RecordingStream,
    entity: &str,
    times: &rerun::TimeColumn,
    values: Vec<f64>,
) -> rerun::RecordingStreamResult<()> {
    stream.send_columns(
        entity,
        [times.clone()],
        rerun::Scalars::update_fields()
            .with_scalars(values)
            .columns_of_unit_batches()?,
    )
}

/// A θ-PSO outcome: planned paths, UAVs moving on `sim_time`, events, violations.
fn log_theta_pso(
    stream: &RecordingStream,
    o: &ThetaPsoOutcome,
    scene: Option<&Mission>,
) -> rerun::RecordingStreamResult<()> {
    if let Some(m) = scene {
        log_clearances(stream, o, m)?;
    }
    stream.send_property(
        "theta_pso",
        &rerun::TextDocument::from_markdown(format!(
            "mission: {}\npipeline: {}\nseed: {}\ncompletion: {:?}\niterations: {}\n\
             feasible: {}\ncost J: {:.4}\nlength: {:.2} m\nduration: {:.2} s\nskyform: {}",
            o.mission,
            o.pipeline,
            o.seed,
            o.completion,
            o.iterations,
            o.feasible(),
            o.cost.total,
            o.path_length,
            o.duration,
            env!("CARGO_PKG_VERSION")
        )),
    )?;
    stream.log_static(
        "theta_pso/plan/centroid",
        &rerun::LineStrips3D::new([o.centroid_path.iter().map(f32x3).collect::<Vec<_>>()])
            .with_colors([rerun::Color::from_rgb(255, 255, 255)])
            .with_labels(["centroid"]),
    )?;
    for t in &o.trajectories {
        let color = uav_color(t.uav);
        let entity = format!("theta_pso/plan/uav_{}", t.uav + 1);
        stream.log_static(
            entity.as_str(),
            &rerun::LineStrips3D::new([t
                .samples
                .iter()
                .map(|s| f32x3(&s.position))
                .collect::<Vec<_>>()])
            .with_colors([color])
            .with_labels([format!("UAV {}", t.uav + 1)]),
        )?;
        let times = rerun::TimeColumn::new_duration_secs("sim_time", t.samples.iter().map(|s| s.t));
        let positions: Vec<[f32; 3]> = t.samples.iter().map(|s| f32x3(&s.position)).collect();
        let velocities: Vec<[f32; 3]> = t
            .samples
            .iter()
            .map(|s| {
                [
                    s.velocity.x as f32,
                    s.velocity.y as f32,
                    s.velocity.z as f32,
                ]
            })
            .collect();
        let uav = format!("theta_pso/uavs/uav_{}", t.uav + 1);
        let style = rerun::Points3D::update_fields()
            .with_colors([color])
            .with_radii([0.5f32])
            .with_labels([format!("UAV {}", t.uav + 1)]);
        log_moving_point(stream, &uav, &times, style, positions.clone())?;
        let arrows = format!("{uav}/velocity");
        stream.log_static(
            arrows.as_str(),
            &rerun::Arrows3D::update_fields().with_colors([color]),
        )?;
        stream.send_columns(
            arrows.as_str(),
            [times],
            rerun::Arrows3D::update_fields()
                .with_origins(positions)
                .with_vectors(velocities)
                .columns_of_unit_batches()?,
        )?;
    }
    for r in &o.reconfigurations {
        for (label, t) in [
            ("t1: transformation starts", r.t1),
            ("t2: shape complete", r.t2),
            ("t3: return starts", r.t3),
            ("t4: back to nominal", r.t4),
        ] {
            stream.set_duration_secs("sim_time", t);
            stream.log(
                "theta_pso/events",
                &rerun::TextLog::new(format!(
                    "{} between '{}' and '{}': {label}",
                    r.shape.name(),
                    r.between[0],
                    r.between[1]
                ))
                .with_level(rerun::TextLogLevel::INFO),
            )?;
        }
    }
    // Inspection passes (eq. 8): the centroid's stretch, and when each begins and ends.
    let speed = o.path_length / o.duration.max(1e-9);
    let walker = crate::planner::path::ArcWalker::new(&o.centroid_path);
    for (pass, result) in o.passes.iter().zip(&o.verification.inspections) {
        let [t0, t1] = pass.time;
        let steps = 20;
        let stretch: Vec<[f32; 3]> = (0..=steps)
            .map(|k| f32x3(&walker.at((t0 + (t1 - t0) * k as f64 / steps as f64) * speed)))
            .collect();
        stream.log_static(
            format!(
                "theta_pso/plan/pass_{}",
                pass.obstacle.replace([' ', '/'], "_")
            )
            .as_str(),
            &rerun::LineStrips3D::new([stretch])
                .with_colors([rerun::Color::from_rgb(230, 110, 230)])
                .with_radii([0.25f32])
                .with_labels([format!("inspection of {}", pass.obstacle)]),
        )?;
        for (label, t) in [("inspection pass starts", t0), ("inspection pass ends", t1)] {
            stream.set_duration_secs("sim_time", t);
            let achieved = result.distance.map_or_else(
                || "no stretch within the band".to_owned(),
                |[lo, hi]| {
                    format!(
                        "{:.1} m within the band, at {lo:.2}-{hi:.2} m",
                        result.achieved
                    )
                },
            );
            stream.log(
                "theta_pso/events",
                &rerun::TextLog::new(format!("{label}: '{}' ({achieved})", pass.obstacle))
                    .with_level(if result.ok {
                        rerun::TextLogLevel::INFO
                    } else {
                        rerun::TextLogLevel::WARN
                    }),
            )?;
        }
    }
    for v in &o.verification.violations {
        stream.set_duration_secs("sim_time", v.location.time);
        let other = v.location.other.as_deref().unwrap_or("");
        stream.log(
            "theta_pso/violations",
            &rerun::Points3D::new([f32x3(&v.location.position)])
                .with_colors([rerun::Color::from_rgb(255, 0, 0)])
                .with_radii([0.8f32])
                .with_labels([format!("{} {:.2} {other}", v.check, v.value)]),
        )?;
        stream.log(
            "theta_pso/events",
            &rerun::TextLog::new(format!(
                "violation: UAV {} {} = {:.3} {other}",
                v.location.uav + 1,
                v.check,
                v.value
            ))
            .with_level(rerun::TextLogLevel::WARN),
        )?;
    }
    stream.reset_time();
    Ok(())
}

/// A FLATLO outcome: references and flown paths per aircraft, the aircraft
/// on `sim_time`, their airspeed, γ, χ and controls as series, the closest
/// approaches as events.
fn log_flatlo(stream: &RecordingStream, o: &FlatloOutcome) -> rerun::RecordingStreamResult<()> {
    let min_separation = o.verification.as_ref().map_or(0.0, |v| v.min_separation);
    stream.send_property(
        "flatlo",
        &rerun::TextDocument::from_markdown(format!(
            "mission: {}\npipeline: {}\nseed: {}\ncompletion: {:?}\naircraft: {}\n\
             arrival: {:.1} s\nduration: {:.1} s\nclosest: {}\nspacing error: {}\n\
             passed: {}\nskyform: {}",
            o.mission,
            o.pipeline,
            o.seed,
            o.completion,
            o.aircraft.len(),
            o.arrival_time,
            o.duration,
            o.closest.map_or("-".to_owned(), |c| format!(
                "{} and {} at {:.0} m",
                c.a + 1,
                c.b + 1,
                c.min_distance
            )),
            o.verification
                .as_ref()
                .map_or("-".to_owned(), |v| format!("{:.3e}", v.max_spacing_error)),
            o.verification
                .as_ref()
                .map_or("no verdict (cancelled)".to_owned(), |v| v
                    .passed
                    .to_string()),
            env!("CARGO_PKG_VERSION")
        )),
    )?;
    for a in &o.aircraft {
        let color = uav_color(a.index);
        let name = format!("aircraft_{}", a.index);
        stream.log_static(
            format!("flatlo/reference/{name}"),
            &rerun::LineStrips3D::new([a
                .reference
                .iter()
                .map(|s| f32x3(&s.position))
                .collect::<Vec<_>>()])
            .with_colors([rerun::Color::from_rgb(170, 170, 170)])
            .with_labels([format!("reference {}", a.index)]),
        )?;
        stream.log_static(
            format!("flatlo/flown/{name}"),
            &rerun::LineStrips3D::new([a
                .flown
                .iter()
                .map(|s| f32x3(&s.position))
                .collect::<Vec<_>>()])
            .with_colors([color])
            .with_labels([format!("aircraft {}", a.index + 1)]),
        )?;
        let times = rerun::TimeColumn::new_duration_secs("sim_time", a.flown.iter().map(|s| s.t));
        let entity = format!("flatlo/aircraft/{name}");
        let style = rerun::Points3D::update_fields()
            .with_colors([color])
            .with_radii([150.0f32])
            .with_labels([format!("aircraft {}", a.index + 1)]);
        let positions = a.flown.iter().map(|s| f32x3(&s.position)).collect();
        log_moving_point(stream, &entity, &times, style, positions)?;
        type Series = fn(&crate::flatlo::FlownSample) -> f64;
        let series: [(&str, Series); 6] = [
            ("airspeed", |s| s.airspeed),
            ("gamma_deg", |s| s.gamma.to_degrees()),
            ("chi_deg", |s| s.chi.to_degrees()),
            ("thrust", |s| s.controls.thrust),
            ("load_factor", |s| s.controls.load_factor),
            ("bank_deg", |s| s.controls.bank.to_degrees()),
        ];
        for (quantity, value) in series {
            let entity = format!("flatlo/{quantity}/{name}");
            log_series(stream, &entity, &times, a.flown.iter().map(value).collect())?;
        }
    }
    stream.set_duration_secs("sim_time", o.arrival_time);
    stream.log(
        "flatlo/events",
        &rerun::TextLog::new(format!(
            "every aircraft on the longitudinal line at t = {:.1} s",
            o.arrival_time
        ))
        .with_level(rerun::TextLogLevel::INFO),
    )?;
    let closest_only: Vec<_> = o.closest.into_iter().collect();
    let pairs = if o.pairs.is_empty() {
        &closest_only
    } else {
        &o.pairs
    };
    for p in pairs {
        stream.set_duration_secs("sim_time", p.time);
        let level = if p.min_distance < min_separation {
            rerun::TextLogLevel::WARN
        } else {
            rerun::TextLogLevel::INFO
        };
        stream.log(
            "flatlo/events",
            &rerun::TextLog::new(format!(
                "closest approach of aircraft {} and {}: {:.0} m",
                p.a + 1,
                p.b + 1,
                p.min_distance
            ))
            .with_level(level),
        )?;
    }
    stream.reset_time();
    Ok(())
}

/// A fleet outcome: agents with trails and their references on `sim_time`,
/// detection ranges, targets, the inter-agent distances (Fig. 13) as series.
fn log_fleet(stream: &RecordingStream, o: &FleetOutcome) -> rerun::RecordingStreamResult<()> {
    stream.send_property(
        "fleet",
        &rerun::TextDocument::from_markdown(format!(
            "mission: {}\npipeline: {}\nseed: {}\ncompletion: {:?}\nagents: {}\n\
             kept apart: {}\nconverged: {}\nskyform: {}",
            o.mission,
            o.pipeline,
            o.seed,
            o.completion,
            o.agents.len(),
            o.kept_apart(),
            o.converged(),
            env!("CARGO_PKG_VERSION")
        )),
    )?;
    let times = rerun::TimeColumn::new_duration_secs("sim_time", o.times.iter().copied());
    for a in &o.agents {
        let color = uav_color(a.index);
        let name = format!("agent_{}", a.index);
        let positions: Vec<[f32; 3]> = a.samples.iter().map(|s| f32x3(&s.position)).collect();
        let references: Vec<[f32; 3]> = a.samples.iter().map(|s| f32x3(&s.reference)).collect();
        stream.log_static(
            format!("fleet/trails/{name}"),
            &rerun::LineStrips3D::new([positions.clone()]).with_colors([color]),
        )?;
        let agent = format!("fleet/agents/{name}");
        let style = rerun::Points3D::update_fields()
            .with_colors([color])
            .with_radii([0.15f32])
            .with_labels([format!("agent {}", a.index + 1)]);
        log_moving_point(stream, &agent, &times, style, positions.clone())?;
        let style = rerun::Points3D::update_fields()
            .with_colors([rerun::Color::from_rgb(200, 200, 200)])
            .with_radii([0.05f32]);
        let reference = format!("fleet/references/{name}");
        log_moving_point(stream, &reference, &times, style, references)?;
    }
    // Named from 1, as the agents are everywhere a person reads.
    for d in &o.distances {
        let entity = format!("fleet/distances/{}_{}", d.a + 1, d.b + 1);
        stream.log_static(
            entity.as_str(),
            &rerun::SeriesLines::new().with_names([format!("agents {}–{}", d.a + 1, d.b + 1)]),
        )?;
        log_series(stream, &entity, &times, d.values.clone())?;
    }
    if !o.distances.is_empty() {
        let c = vec![o.safety_distance; o.times.len()];
        stream.log_static(
            "fleet/distances/safety_c",
            &rerun::SeriesLines::new().with_names(["c (safety distance)"]),
        )?;
        log_series(stream, "fleet/distances/safety_c", &times, c)?;
    }
    let z = o
        .agents
        .first()
        .and_then(|a| a.samples.first())
        .map_or(0.0, |s| s.position.z as f32);
    for (k, t) in o.targets.iter().enumerate() {
        stream.set_duration_secs("sim_time", t.time);
        stream.log(
            "fleet/target",
            &rerun::Points3D::new([[t.position.x as f32, t.position.y as f32, z]])
                .with_colors([rerun::Color::from_rgb(255, 215, 0)])
                .with_radii([0.1f32])
                .with_labels([format!("target {}", k + 1)]),
        )?;
        let text = match t.converged_after {
            Some(after) => format!(
                "target {} appears; formation reached {after:.2} s later",
                k + 1
            ),
            None => format!("target {} appears; formation NOT reached", k + 1),
        };
        stream.log("fleet/events", &rerun::TextLog::new(text))?;
    }
    for (label, closest) in [
        ("agents", &o.closest_agents),
        ("obstacle", &o.closest_obstacle),
    ] {
        if let Some(c) = closest {
            stream.set_duration_secs("sim_time", c.time);
            let level = if c.distance < o.safety_distance {
                rerun::TextLogLevel::WARN
            } else {
                rerun::TextLogLevel::INFO
            };
            stream.log(
                "fleet/events",
                &rerun::TextLog::new(format!(
                    "closest approach ({label}): agent {} and {} at {:.3} m",
                    c.a + 1,
                    c.b,
                    c.distance
                ))
                .with_level(level),
            )?;
        }
    }
    stream.reset_time();
    Ok(())
}

/// `skyform record`: the mission scene alone.
pub fn record_scene(
    mission: &Mission,
    sinks: &Sinks,
) -> Result<(Option<Finished>, Vec<String>), RecordError> {
    let mut warnings = Vec::new();
    let recorder = Recorder::start(&mission.name, sinks, &mut warnings)?;
    Ok((
        recorder.map(|mut r| {
            r.log_mission(mission);
            r.finish()
        }),
        warnings,
    ))
}

/// An `.rrd` can only be written into an existing directory.
fn check_rrd_path(path: &Path) -> Result<(), String> {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() && !dir.is_dir() => {
            Err(format!("{} is not a directory", dir.display()))
        }
        _ => Ok(()),
    }
}

//! Rerun recordings: the mission scene, live θ-PSO progress and the results,
//! saved to `.rrd` and/or streamed to a viewer.
//!
//! Here the sinks, the recorder and its worker; the entity paths of the
//! layout documented in `docs/rerun.md` are all in `paths.rs`, the viewer
//! layouts in `layout.rs`, the scene in `scene.rs` and each pipeline's
//! outcome in its own file (`theta_pso.rs`, `flatlo.rs`, `fleet.rs`).
//!
//! `world` is right-handed, Z up, metres, with `world/bounds`,
//! `world/obstacles`, `world/route`, `world/iwps` static. Each pipeline logs
//! under its own root (`theta_pso/…`, `flatlo/…`, `fleet/…`), its log lines
//! at `<root>/log`; θ-PSO's best path of each iteration and cost terms are
//! on the `iteration` timeline, every flight on `sim_time`.
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

use crate::mission::Mission;
use crate::outcome::Outcome;
use crate::pipelines::{Event, Kind, Level, Observer};

mod flight;
mod layout;
pub mod paths;
mod scene;
mod sketch;
mod swarm;

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
        terms: Vec<(&'static str, f64)>,
        path: Vec<[f32; 3]>,
    },
    Log(Level, String),
    Outcome(Box<Outcome>),
    /// A live plan, the `revision`-th of the designer's session.
    Live(u64, Box<Outcome>),
    /// A flight check and its report's text.
    Flights(Box<crate::flight::Recording>, String),
}

/// A recording in progress. `finish` (or drop) flushes it and closes the file.
pub struct Recorder {
    queue: Sender<Message>,
    /// Kept to drop the oldest message when the queue is full.
    oldest: Receiver<Message>,
    worker: Option<JoinHandle<()>>,
    dropped: usize,
    /// The `.rrd` being written: it replaces its destination (atomically,
    /// keeping that file's mode) when the recording is finished.
    file: Option<crate::base::atomic::Pending>,
}

/// What a finished recording left behind.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finished {
    /// The `.rrd` written, with its size in bytes.
    pub file: Option<(PathBuf, u64)>,
    /// Messages dropped because the queue was full.
    pub dropped: usize,
    /// Why the `.rrd` could not be put in place, if it could not.
    pub error: Option<String>,
}

impl Recorder {
    /// Opens the sinks and starts the worker for a run of `pipeline` (its
    /// layout, its log path), or of none (the scene alone). `None` when
    /// `sinks` is empty or every viewer sink failed; `warnings` gets one line
    /// per viewer that could not be reached or started.
    pub fn start(
        name: &str,
        pipeline: Option<Kind>,
        sinks: &Sinks,
        warnings: &mut Vec<String>,
    ) -> Result<Option<Recorder>, RecordError> {
        let mut boxes: Vec<Box<dyn LogSink>> = Vec::new();
        let mut file = None;
        if let Some(path) = &sinks.rrd {
            let error = |message: String| RecordError::File {
                path: path.display().to_string(),
                message,
            };
            check_rrd_path(path).map_err(error)?;
            let pending = crate::base::atomic::create(path).map_err(|e| error(e.to_string()))?;
            let sink = FileSink::new(pending.temporary_path()).map_err(|e| error(e.to_string()))?;
            boxes.push(Box::new(sink));
            file = Some(pending);
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
        let _ = layout::layout(pipeline.unwrap_or_default())
            .send(&stream, rerun::blueprint::BlueprintActivation::default());
        let (queue, inbox) = crossbeam_channel::bounded(QUEUE_CAPACITY);
        let oldest = inbox.clone();
        let worker = std::thread::Builder::new()
            .name("rerun-recorder".into())
            .spawn(move || run_worker(stream, inbox, pipeline))
            .map_err(|e| RecordError::Stream(e.to_string()))?;
        Ok(Some(Recorder {
            queue,
            oldest,
            worker: Some(worker),
            dropped: 0,
            file,
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

    /// Logs a flight check (`skyform fly --rrd`): the plan as written, the
    /// envelope, the worst flights, the report.
    pub fn log_flights(&mut self, recording: crate::flight::Recording, report: String) {
        self.send(Message::Flights(Box::new(recording), report));
    }

    /// Logs a live plan of the designer as revision `revision`: its plan
    /// entities on the `revision` timeline, so each replaces the last in the
    /// view and the timeline keeps them all.
    pub fn log_live(&mut self, revision: u64, outcome: &Outcome) {
        self.send(Message::Live(revision, Box::new(outcome.clone())));
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
        let mut error = None;
        let file = self.file.take().and_then(|pending| {
            let path = pending.destination().to_owned();
            match pending.commit() {
                Ok(()) => {
                    let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
                    Some((path, size))
                }
                Err(e) => {
                    error = Some(format!("cannot write {}: {e}", path.display()));
                    None
                }
            }
        });
        Finished {
            file,
            dropped: self.dropped,
            error,
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
            Event::Iteration {
                iteration,
                terms,
                path,
                ..
            } => self.send(Message::Iteration {
                iteration,
                terms: terms.to_vec(),
                path: path.iter().map(f32x3).collect(),
            }),
            Event::Log(level, text) => self.send(Message::Log(level, text.to_owned())),
            Event::Stage(_) | Event::Progress(_) | Event::Vehicles { .. } => {}
        }
    }
}

pub(crate) fn f32x3(p: &Point3<f64>) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}

/// Vehicle `n`'s colour, the same as on the designer's map.
fn uav_color(n: usize) -> rerun::Color {
    let [r, g, b] = crate::outcome::tracks::vehicle_color(n);
    rerun::Color::from_rgb(r, g, b)
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
/// iterations that arrive together into one `send_columns` per series.
fn run_worker(stream: RecordingStream, inbox: Receiver<Message>, pipeline: Option<Kind>) {
    // Only a pipeline logs lines; the scene alone never does.
    let log = paths::log(pipeline.unwrap_or_default());
    let root = paths::root(pipeline.unwrap_or_default());
    let mut pending: Vec<swarm::Iteration> = Vec::new();
    // The mission of the scene, for what an outcome is measured against.
    let mut scene: Option<Box<Mission>> = None;
    while let Ok(first) = inbox.recv() {
        let mut batch = vec![first];
        batch.extend(inbox.try_iter());
        for message in batch {
            match message {
                Message::Iteration {
                    iteration,
                    terms,
                    path,
                } => pending.push((iteration, terms, path)),
                other => {
                    swarm::flush_iterations(&stream, &root, &mut pending);
                    if let Message::Scene(m) = &other {
                        scene = Some(m.clone());
                    }
                    log_message(&stream, other, scene.as_deref(), &log);
                }
            }
        }
        swarm::flush_iterations(&stream, &root, &mut pending);
    }
    let _ = stream.flush_with_timeout(Duration::from_secs(10));
    drop(stream);
}

/// Logs one message; `log` is where the run's log lines go (`paths::log`).
fn log_message(stream: &RecordingStream, message: Message, scene: Option<&Mission>, log: &str) {
    let result = match message {
        Message::Scene(mission) => scene::log_scene(stream, &mission),
        Message::Outcome(outcome) => log_outcome(stream, &outcome, scene),
        Message::Log(level, text) => {
            let level = match level {
                Level::Info => rerun::TextLogLevel::INFO,
                Level::Warn => rerun::TextLogLevel::WARN,
            };
            stream.log(log, &rerun::TextLog::new(text).with_level(level))
        }
        Message::Iteration { .. } => Ok(()),
        Message::Flights(recording, report) => flight::log_flights(stream, &recording, &report),
        Message::Live(revision, outcome) => log_live(stream, revision, &outcome),
    };
    // A logging error (a sink gone) must not stop the run; the recording is
    // best effort from here on.
    let _ = result;
}

/// An outcome as its pipeline draws itself (`PipelineOutcome::sketch`).
fn log_outcome(
    stream: &RecordingStream,
    outcome: &Outcome,
    scene: Option<&Mission>,
) -> rerun::RecordingStreamResult<()> {
    let mut sketch = sketch::RerunSketch::new(stream);
    outcome.face().sketch(scene, &mut sketch);
    stream.reset_time();
    sketch.result
}

/// A live plan on the `revision` timeline: the centroid path, each UAV's
/// track and the verdict (θ-PSO); FLATLO's flown paths and its verdict.
fn log_live(
    stream: &RecordingStream,
    revision: u64,
    outcome: &Outcome,
) -> rerun::RecordingStreamResult<()> {
    stream.set_time_sequence("revision", revision as i64);
    let verdict = match outcome.verdict() {
        crate::outcome::Verdict::Passed => "feasible".to_owned(),
        crate::outcome::Verdict::Failed(why) => format!("INFEASIBLE: {why}"),
        crate::outcome::Verdict::Cancelled => "cancelled".to_owned(),
    };
    let tracks = outcome.tracks();
    for (k, track) in tracks.iter().enumerate() {
        let points: Vec<[f32; 3]> = track.samples.iter().map(|s| f32x3(&s.position)).collect();
        stream.log(
            paths::live_track(k),
            &rerun::LineStrips3D::new([points]).with_colors([uav_color(k)]),
        )?;
    }
    let mut sketch = sketch::RerunSketch::at_current_time(stream);
    outcome.face().sketch_live(paths::LIVE_PLAN, &mut sketch);
    sketch.result?;
    let warm = outcome
        .face()
        .warm_from()
        .unwrap_or_else(|| "cold".to_owned());
    stream.log(
        paths::LIVE_EVENTS,
        &rerun::TextLog::new(format!(
            "live plan {revision}: {verdict} ({warm}); {}",
            outcome.headline()
        )),
    )?;
    stream.reset_time();
    Ok(())
}

/// `skyform record`: the mission scene alone.
pub fn record_scene(
    mission: &Mission,
    sinks: &Sinks,
) -> Result<(Option<Finished>, Vec<String>), RecordError> {
    let mut warnings = Vec::new();
    let recorder = Recorder::start(&mission.name, None, sinks, &mut warnings)?;
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

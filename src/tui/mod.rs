//! The terminal mission designer.
//!
//! The state/update/view split of ratatui's component apps: `app.rs` holds
//! the state (components that own theirs: `editor.rs`, `board.rs`,
//! `overlay.rs`, `camera.rs`, `replay.rs`) and its one mutator, which hands
//! each action to the component that owns it; `action.rs` is the vocabulary
//! of changes, `input.rs` turns keys and mouse into actions, `view/` draws
//! the state, and `jobs.rs` runs pipelines on worker threads that report
//! through a channel.
//! The loop below waits on input *or* job messages, so it never spins while
//! idle and never blocks while a job runs.

pub mod action;
pub mod app;
pub mod board;
pub mod camera;
pub mod document;
pub mod editor;
pub mod export;
pub mod fields;
pub mod find;
#[doc(hidden)]
pub mod fixtures;
mod import;
pub mod input;
pub mod jobs;
pub mod keys;
pub mod live;
pub mod overlay;
pub mod recovery;
pub mod replay;
pub mod status;
pub mod view;

use std::io::{self, IsTerminal};
use std::path::{Path, PathBuf};
use std::thread;
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, after, never, select, unbounded};
use ratatui::DefaultTerminal;
use ratatui::crossterm::event::{self, DisableMouseCapture, EnableMouseCapture, Event};
use ratatui::crossterm::execute;
use ratatui::layout::Rect;

pub use action::Action;
pub use app::App;
pub use document::Document;

use crate::mission;

/// How often the screen refreshes while a job runs (elapsed times, gauges).
const TICK: Duration = Duration::from_millis(100);

/// The document for `path`: the built-in default without one; the file when
/// it exists (validation errors are shown in the TUI, not refused); a new,
/// unsaved document to be written there when it does not. A file that is not
/// a mission at all is an error naming each problem with its line.
pub fn open_document(path: Option<&Path>) -> Result<(Document, Option<String>), String> {
    let builtin = mission::BUILTIN[0].text;
    let Some(path) = path else {
        return Ok((
            Document::new(mission::default_mission().mission, None)
                .with_source(builtin)
                .with_builtin(mission::BUILTIN[0].file_name),
            None,
        ));
    };
    if !path.exists() {
        let doc = new_document(path)?;
        let note = format!(
            "{} is a new mission (a box, a start, a goal): Ctrl-s creates the file",
            path.display()
        );
        return Ok((doc, Some(note)));
    }
    let text = mission::read(path).map_err(|e| e.to_string())?;
    let name = path.display().to_string();
    let checked = crate::outcome::diagnose::check_text(&text, Some(&name));
    match checked.mission {
        Some(m) => {
            let errors = checked.report.error_count();
            let note =
                (errors > 0).then(|| format!("{name}: {errors} error(s) to fix before running"));
            Ok((
                Document::new(m, Some(path.to_path_buf())).with_source(text),
                note,
            ))
        }
        None => {
            // A file that is not TOML at all can give hundreds of errors:
            // the first few say what it is, `check` lists them all.
            const SHOWN: usize = 8;
            let all: Vec<String> = checked.report.errors().map(|d| d.to_string()).collect();
            let mut text = all
                .iter()
                .take(SHOWN)
                .cloned()
                .collect::<Vec<_>>()
                .join("\n");
            if all.len() > SHOWN {
                text.push_str(&format!(
                    "\n… and {} more error(s); `skyform check {name}` lists them all",
                    all.len() - SHOWN
                ));
            }
            Err(format!("{name} is not a valid mission:\n{text}"))
        }
    }
}

/// A new, unsaved mission to be written at `path`: the minimal template
/// (`mission::template_text`), named after the file. A shipped mission is
/// copied only on purpose (`skyform new --from`, the open dialog).
pub fn new_document(path: &Path) -> Result<Document, String> {
    let name = mission::name_for(path);
    let m = mission::template(&name).map_err(|e| e.to_string())?;
    Ok(Document::new_file(m, path.to_path_buf()).with_source(mission::template_text(&name)))
}

/// Runs the TUI on `path` (or the built-in mission) until the operator
/// quits; returns the exit code (128 + the signal's number when a signal
/// ended it, as shells expect).
pub fn run(path: Option<PathBuf>, live: bool) -> Result<u8, String> {
    let (doc, note) = open_document(path.as_deref())?;
    if !io::stdout().is_terminal() || !io::stdin().is_terminal() {
        return Err("the mission designer needs a terminal; for scripts use `skyform run` or `skyform check` (see --help)".into());
    }
    let cwd = std::env::current_dir().unwrap_or_else(|_| PathBuf::from("."));
    let mut app = App::new(doc, cwd);
    if let Some(note) = note {
        app.show_error(note);
    }
    app.enable_recovery(match &path {
        Some(p) => recovery::Origin::File(p.clone()),
        None => recovery::Origin::Builtin(mission::BUILTIN[0].file_name.to_owned()),
    });
    if live {
        app.enable_live();
    } else {
        app.hold_live_off("--no-live; L turns it on".to_owned());
    }
    let signals = spawn_signals();

    let mut terminal =
        ratatui::try_init().map_err(|e| format!("cannot set up the terminal: {e}"))?;
    install_panic_hook();
    // Mouse is a convenience: a terminal without it still works by keyboard.
    let _ = execute!(io::stdout(), EnableMouseCapture);
    let result = event_loop(&mut terminal, &mut app, &signals);
    // Whatever ended the loop, unsaved edits are on disk before anything else.
    app.keep_recovery(Instant::now(), true);
    // Cancelled jobs stop at their next iteration; let them finish their
    // recordings before the process ends.
    app.wait_for_jobs(Duration::from_secs(5));
    let _ = execute!(io::stdout(), DisableMouseCapture);
    ratatui::restore();
    let code = result.map_err(|e| format!("terminal error: {e}"))?;
    if code != 0
        && let Some(copy) = app.recovery_path().filter(|p| p.exists())
    {
        eprintln!(
            "skyform: stopped by a signal; unsaved changes are kept in {}",
            copy.display()
        );
    }
    Ok(code)
}

/// SIGTERM, SIGHUP (the terminal window closed) and SIGINT (from `kill`:
/// in the designer Ctrl-c is a key) end the designer as `q` does, without
/// the unsaved-changes question: the recovery copy keeps the edits.
#[cfg(unix)]
fn spawn_signals() -> Receiver<i32> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let (tx, rx) = unbounded();
    match signal_hook::iterator::Signals::new([SIGTERM, SIGHUP, SIGINT]) {
        Ok(mut signals) => {
            let _ = thread::Builder::new()
                .name("skyform-signals".into())
                .spawn(move || {
                    for signal in signals.forever() {
                        if tx.send(signal).is_err() {
                            break;
                        }
                    }
                });
        }
        Err(e) => eprintln!("warning: signals will not restore the terminal: {e}"),
    }
    rx
}

#[cfg(not(unix))]
fn spawn_signals() -> Receiver<i32> {
    never()
}

/// ratatui's hook restores the terminal on a panic; only a panic of the UI
/// thread should do that. A job's panic is caught by the job and shown as a
/// failed job, so it must neither restore the terminal nor print over the UI.
fn install_panic_hook() {
    let ui = thread::current().id();
    let restore_and_report = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if thread::current().id() == ui {
            let _ = execute!(io::stdout(), DisableMouseCapture);
            restore_and_report(info);
        }
    }));
}

/// Reads terminal events on a thread so the loop can wait on them and on
/// jobs at once.
fn spawn_input() -> Receiver<io::Result<Event>> {
    let (tx, rx) = unbounded();
    let _ = thread::Builder::new()
        .name("skyform-input".into())
        .spawn(move || {
            loop {
                let event = event::read();
                let failed = event.is_err();
                if tx.send(event).is_err() || failed {
                    break;
                }
            }
        });
    rx
}

/// Returns the exit code: 0, or 128 + a signal that ended it.
fn event_loop(
    terminal: &mut DefaultTerminal,
    app: &mut App,
    signals: &Receiver<i32>,
) -> io::Result<u8> {
    let input = spawn_input();
    let job_messages = app.job_messages().clone();
    let mut redraw = true;
    let mut code = 0u8;
    // What the last frame showed where: clicks are read against it.
    let mut drawn = None;
    loop {
        if redraw {
            terminal.draw(|frame| drawn = view::draw(frame, app, Instant::now()))?;
        }
        if app.should_quit() {
            return Ok(code);
        }
        let tick = match app.wake_at() {
            Some(at) => crossbeam_channel::at(at.min(Instant::now() + TICK)),
            None if app.wants_tick() => after(TICK),
            None => never(),
        };
        redraw = false;
        select! {
            recv(input) -> event => match event {
                Ok(event) => redraw |= handle(terminal, app, drawn.as_ref(), event?)?,
                Err(_) => return Err(io::Error::other("the terminal input closed")),
            },
            recv(job_messages) -> msg => {
                if let Ok(msg) = msg {
                    app.on_job_msg(msg, Instant::now());
                    redraw = true;
                }
            },
            recv(tick) -> _ => {
                app.tick(TICK);
                redraw = true;
            },
            recv(signals) -> signal => {
                if let Ok(signal) = signal {
                    code = 128u8.saturating_add(u8::try_from(signal).unwrap_or(0));
                    app.quit_now();
                    redraw = true;
                }
            },
        }
        // Take what else is waiting before drawing once.
        redraw |= app.drain_job_messages();
        while let Ok(event) = input.try_recv() {
            redraw |= handle(terminal, app, drawn.as_ref(), event?)?;
        }
        // A live run due by now starts (after every edit's debounce).
        if app.wake_at().is_some_and(|at| at <= Instant::now()) {
            app.poll_live(Instant::now());
            redraw = true;
        }
    }
}

/// Applies one terminal event; returns whether the screen must be redrawn.
fn handle(
    terminal: &DefaultTerminal,
    app: &mut App,
    drawn: Option<&view::Drawn>,
    event: Event,
) -> io::Result<bool> {
    let size = terminal.size()?;
    let too_small = view::layout(Rect::new(0, 0, size.width, size.height)).is_none();
    let action = match event {
        // The "too small" screen hides the designer: only quitting acts.
        Event::Key(key) if too_small => {
            input::key_action(app, key).filter(|a| matches!(a, Action::Quit))
        }
        Event::Mouse(_) if too_small => None,
        Event::Key(key) => input::key_action(app, key),
        Event::Mouse(mouse) => drawn.and_then(|d| input::mouse_action(app, mouse, d)),
        Event::Resize(..) => return Ok(true),
        _ => None,
    };
    Ok(match action {
        Some(action) => {
            app.update(action);
            app.keep_recovery(Instant::now(), false);
            true
        }
        None => false,
    })
}

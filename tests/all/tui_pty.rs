//! End to end: the real binary in a pseudo-terminal, driven by keystrokes,
//! its screen read back through a terminal emulator (vt100): edit, run, save
//! and quit; a `kill -9` and the recovery copy; SIGTERM during a run.

#![cfg(unix)]

use std::io::{Read, Write};
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::{Duration, Instant};

use portable_pty::{Child, CommandBuilder, MasterPty, PtySize, native_pty_system};
use skyform::mission;

const ROWS: u16 = 40;
const COLS: u16 = 130;

struct Session {
    master: Box<dyn MasterPty + Send>,
    writer: Box<dyn Write + Send>,
    screen: Arc<Mutex<vt100::Parser>>,
    child: Box<dyn Child + Send + Sync>,
}

impl Session {
    fn contents(&self) -> String {
        self.screen.lock().unwrap().screen().contents()
    }

    /// Waits until the screen shows `text`; fails with the screen if it never does.
    fn wait_for(&self, text: &str, timeout: Duration) {
        let deadline = Instant::now() + timeout;
        while Instant::now() < deadline {
            if self.contents().contains(text) {
                return;
            }
            thread::sleep(Duration::from_millis(50));
        }
        panic!("'{text}' never appeared; the screen:\n{}", self.contents());
    }

    fn send(&mut self, keys: &str) {
        self.writer.write_all(keys.as_bytes()).unwrap();
        self.writer.flush().unwrap();
    }

    /// Waits for the process to end; its exit code.
    fn wait_exit(&mut self, timeout: Duration) -> u32 {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                return status.exit_code();
            }
            assert!(
                Instant::now() < deadline,
                "skyform did not exit; the screen:\n{}",
                self.contents()
            );
            thread::sleep(Duration::from_millis(50));
        }
    }

    fn signal(&self, signal: &str) {
        let pid = self.child.process_id().expect("a pid");
        let status = std::process::Command::new("kill")
            .args([signal, &pid.to_string()])
            .status()
            .unwrap();
        assert!(status.success());
    }

    fn cooked(&self) -> bool {
        let flags = self.local_flags();
        flags.iter().any(|f| f == "ICANON") && flags.iter().any(|f| f == "ECHO")
    }

    /// Local flags of the terminal (ICANON, ECHO, …) as their names.
    fn local_flags(&self) -> Vec<String> {
        let termios = self.master.get_termios().expect("termios of the pty");
        format!("{:?}", termios.local_flags)
            .split(|c: char| !c.is_ascii_alphanumeric())
            .filter(|s| !s.is_empty())
            .map(str::to_owned)
            .collect()
    }
}

/// Starts skyform on `file` in a fresh pseudo-terminal, recovery copies
/// kept in `state`.
fn launch(file: &std::path::Path, state: &std::path::Path) -> Session {
    launch_sized(file, state, ROWS, COLS)
}

fn launch_sized(file: &std::path::Path, state: &std::path::Path, rows: u16, cols: u16) -> Session {
    launch_with(file, state, rows, cols, &[])
}

/// `launch_sized` with more arguments after the file.
fn launch_with(
    file: &std::path::Path,
    state: &std::path::Path,
    rows: u16,
    cols: u16,
    args: &[&str],
) -> Session {
    let pair = native_pty_system()
        .openpty(PtySize {
            rows,
            cols,
            pixel_width: 0,
            pixel_height: 0,
        })
        .unwrap();
    let mut cmd = CommandBuilder::new(env!("CARGO_BIN_EXE_skyform"));
    cmd.arg(file);
    cmd.args(args);
    if let Some(dir) = file.parent() {
        cmd.cwd(dir);
    }
    cmd.env("TERM", "xterm-256color");
    cmd.env("SKYFORM_STATE_DIR", state);
    let child = pair.slave.spawn_command(cmd).unwrap();
    drop(pair.slave);

    let screen = Arc::new(Mutex::new(vt100::Parser::new(
        std::num::NonZero::new(rows).unwrap(),
        std::num::NonZero::new(cols).unwrap(),
        0,
    )));
    let mut reader = pair.master.try_clone_reader().unwrap();
    let feed = Arc::clone(&screen);
    thread::spawn(move || {
        let mut buf = [0u8; 8192];
        while let Ok(n) = reader.read(&mut buf) {
            if n == 0 {
                break;
            }
            feed.lock().unwrap().process(&buf[..n]);
        }
    });
    let writer = pair.master.take_writer().unwrap();
    Session {
        master: pair.master,
        writer,
        screen,
        child,
    }
}

fn bridge_copy(dir: &std::path::Path) -> std::path::PathBuf {
    let file = dir.join("bridge.toml");
    std::fs::copy(
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/missions/bridge-inspection.toml"
        ),
        &file,
    )
    .unwrap();
    file
}

/// The bridge with 20,000 iterations: a run long enough to be interrupted.
fn long_bridge_copy(dir: &std::path::Path) -> std::path::PathBuf {
    let file = bridge_copy(dir);
    let text = std::fs::read_to_string(&file).unwrap();
    std::fs::write(
        &file,
        text.replace("iterations = 150", "iterations = 20000"),
    )
    .unwrap();
    file
}

#[test]
fn edit_run_save_quit_in_a_real_terminal() {
    let dir = tempfile::tempdir().unwrap();
    let state = tempfile::tempdir().unwrap();
    let file = bridge_copy(dir.path());
    let before = mission::load(&file).unwrap().mission;
    let mut s = launch(&file, state.path());

    s.wait_for("Inspector", Duration::from_secs(30));
    s.wait_for("bridge.toml", Duration::from_secs(5));
    assert!(
        !s.cooked(),
        "the TUI runs in raw mode: {:?}",
        s.local_flags()
    );

    s.send("a");
    s.wait_for("added 'obstacle 10'", Duration::from_secs(10));
    s.wait_for("modified", Duration::from_secs(5));

    s.send("r");
    s.wait_for("job 1 done", Duration::from_secs(120));
    assert!(s.contents().contains("feasible"), "{}", s.contents());

    s.send("\x13"); // Ctrl-s
    s.wait_for("saved", Duration::from_secs(10));

    s.send("q");
    assert_eq!(s.wait_exit(Duration::from_secs(20)), 0);
    assert!(
        s.cooked(),
        "terminal left in raw mode: {:?}",
        s.local_flags()
    );

    let after = mission::load(&file).unwrap().mission;
    assert_eq!(after.obstacles.len(), before.obstacles.len() + 1);
    let added = after.obstacles.last().unwrap();
    assert_eq!(added.name, "obstacle 10");
    assert_eq!(
        after.obstacles[..before.obstacles.len()],
        before.obstacles[..]
    );
    // Saved and quit cleanly: no recovery copy is left.
    assert_eq!(std::fs::read_dir(state.path()).unwrap().count(), 0);
    // The save edited the file in place: only the new obstacle was added.
    let original = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/missions/bridge-inspection.toml"
    ))
    .unwrap();
    let saved = std::fs::read_to_string(&file).unwrap();
    assert!(saved.starts_with(&original), "the file's own text stays");
}

/// Issue 12: an obstacle added, the process killed with SIGKILL (nothing can
/// run on the way out), started again on the same file: the recovery is
/// offered, accepted and saved; the file has the obstacle.
#[test]
fn a_killed_designer_offers_its_unsaved_edits_back() {
    let dir = tempfile::tempdir().unwrap();
    let state = tempfile::tempdir().unwrap();
    let file = bridge_copy(dir.path());
    let before = mission::load(&file).unwrap().mission;

    let mut s = launch(&file, state.path());
    s.wait_for("Inspector", Duration::from_secs(30));
    s.send("a");
    s.wait_for("added 'obstacle 10'", Duration::from_secs(10));
    // The copy is written within about a second of the edit.
    let deadline = Instant::now() + Duration::from_secs(5);
    while std::fs::read_dir(state.path()).unwrap().count() == 0 {
        assert!(Instant::now() < deadline, "no recovery copy was written");
        thread::sleep(Duration::from_millis(50));
    }
    s.signal("-KILL");
    s.wait_exit(Duration::from_secs(10));
    assert_eq!(
        mission::load(&file).unwrap().mission,
        before,
        "nothing saved"
    );

    let mut s = launch(&file, state.path());
    s.wait_for("Recover unsaved changes?", Duration::from_secs(30));
    s.wait_for("1 change(s)", Duration::from_secs(5));
    s.send("y");
    s.wait_for("restored 1 unsaved change(s)", Duration::from_secs(10));
    s.send("\x13"); // Ctrl-s
    s.wait_for("saved", Duration::from_secs(10));
    s.send("q");
    assert_eq!(s.wait_exit(Duration::from_secs(20)), 0);

    let after = mission::load(&file).unwrap().mission;
    assert_eq!(after.obstacles.len(), before.obstacles.len() + 1);
    assert_eq!(after.obstacles.last().unwrap().name, "obstacle 10");
    assert_eq!(std::fs::read_dir(state.path()).unwrap().count(), 0);
}

/// Issue 12: SIGTERM while a recorded job runs: the designer cancels the
/// job, closes its recording, gives the terminal back (ICANON and ECHO on)
/// and exits with 128 + 15.
#[test]
fn sigterm_during_a_run_restores_the_terminal_and_closes_the_recording() {
    let dir = tempfile::tempdir().unwrap();
    let state = tempfile::tempdir().unwrap();
    let file = long_bridge_copy(dir.path());

    let mut s = launch(&file, state.path());
    s.wait_for("Inspector", Duration::from_secs(30));
    s.send("e"); // record runs to an .rrd beside the mission
    s.wait_for("recorded to an .rrd", Duration::from_secs(10));
    s.send("r");
    s.wait_for("started with seed", Duration::from_secs(10));
    thread::sleep(Duration::from_millis(1500));
    s.signal("-TERM");
    assert_eq!(s.wait_exit(Duration::from_secs(30)), 128 + 15);
    assert!(
        s.cooked(),
        "terminal left in raw mode: {:?}",
        s.local_flags()
    );

    let rrd: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rrd"))
        .collect();
    assert_eq!(rrd.len(), 1, "{rrd:?}");
    let file = std::fs::File::open(&rrd[0]).unwrap();
    let messages: Vec<_> = re_log_encoding::DecoderApp::decode_eager(std::io::BufReader::new(file))
        .expect("an rrd")
        .collect::<Result<_, _>>()
        .expect("every message decodes: the recording was closed");
    assert!(messages.len() > 3, "{} messages", messages.len());
}

/// Issue 16 at 80×24, the smallest screen the designer takes: the help
/// scrolls to the Run keys, a run starts, is cancelled, and the jobs panel
/// shows the share it got through (not a full bar).
#[test]
fn at_80_by_24_help_scrolls_to_the_run_keys_and_a_cancel_shows_its_share() {
    let dir = tempfile::tempdir().unwrap();
    let state = tempfile::tempdir().unwrap();
    let file = long_bridge_copy(dir.path());
    let mut s = launch_sized(&file, state.path(), 24, 80);
    // The map has the width: the inspector is folded away.
    s.wait_for("Tab: inspector and jobs", Duration::from_secs(30));

    s.send("?");
    s.wait_for("Keys", Duration::from_secs(5));
    let mut found = false;
    for _ in 0..60 {
        if s.contents().contains("run θ-PSO") {
            found = true;
            break;
        }
        s.send("\x1b[B"); // ↓
        thread::sleep(Duration::from_millis(60));
    }
    assert!(
        found,
        "the Run keys never scrolled into view:\n{}",
        s.contents()
    );
    s.send("q"); // any other key closes the help
    thread::sleep(Duration::from_millis(200));

    s.send("r");
    s.wait_for("started with seed", Duration::from_secs(10));
    thread::sleep(Duration::from_millis(1500));
    s.send("x");
    s.wait_for("cancelled", Duration::from_secs(30));
    // The jobs panel folds away while the map has the focus at 80 columns:
    // Tab, Tab unfolds it and focuses it.
    s.send("\t\t");
    s.wait_for("Jobs", Duration::from_secs(5));
    let screen = s.contents();
    assert!(screen.contains("job 1 cancelled"), "{screen}");
    let line = screen
        .lines()
        .find(|l| l.contains("θ-PSO s") && l.contains('%'))
        .unwrap_or_else(|| panic!("no job line:\n{screen}"));
    let percent: u32 = line
        .split('%')
        .next()
        .and_then(|head| head.split_whitespace().last())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no percentage in {line:?}"));
    assert!(percent < 100, "a cancelled job shows {percent}%: {line}");
    s.send("q");
    assert_eq!(s.wait_exit(Duration::from_secs(20)), 0);
    assert!(s.cooked());
}

/// Sends `keys` and waits for `shown` (the status line's report of the edit,
/// a title): one step of a user's session.
fn step(s: &mut Session, keys: &str, shown: &str) {
    s.send(keys);
    s.wait_for(shown, Duration::from_secs(10));
}

/// Issue 24, "Done when": the turbines mission built from `skyform NEW.toml`
/// with keys only (four UAVs in a diamond inspecting two towers 12 m apart,
/// the route between them, 200 m × 150 m, band 20-40 m), saved: the file has
/// no [origin], nothing of the bridge, the two towers and the four slots.
#[test]
fn a_new_mission_built_with_keys_only_saves_what_was_typed() {
    const DOWN: &str = "\x1b[B";
    const UP: &str = "\x1b[A";
    let dir = tempfile::tempdir().unwrap();
    let state = tempfile::tempdir().unwrap();
    let file = dir.path().join("turbines.toml");
    let mut s = launch(&file, state.path());
    s.wait_for("is a new mission", Duration::from_secs(30));

    // The box and the band.
    step(&mut s, "n", "Inspector · Bounds");
    step(&mut s, &format!("\t{DOWN}200\r"), "x max (m) = 200");
    step(&mut s, &format!("{DOWN}{DOWN}150\r"), "y max (m) = 150");
    step(&mut s, &format!("{DOWN}{DOWN}40\r"), "z max (m) = 40");
    step(&mut s, &format!("{UP}20\r"), "z min (m) = 20");
    // Start and goal inside it, on the line between the towers.
    step(&mut s, "n", "Inspector · Start");
    step(&mut s, &format!("{DOWN}75\r"), "y (m) = 75");
    step(&mut s, &format!("{DOWN}30\r"), "z (m) = 30");
    step(&mut s, "n", "Inspector · Goal");
    step(&mut s, &format!("{UP}{UP}190\r"), "x (m) = 190");
    step(&mut s, &format!("{DOWN}75\r"), "y (m) = 75");
    step(&mut s, &format!("{DOWN}30\r"), "z (m) = 30");
    // Two inspected towers 12 m apart, centre to centre.
    for (k, y) in [(1, "69"), (2, "81")] {
        step(&mut s, "a", &format!("added 'obstacle {k}'"));
        step(
            &mut s,
            &format!("\r\x15tower {k}\r"),
            &format!("Obstacle {k} 'tower {k}'"),
        );
        step(
            &mut s,
            &format!("{DOWN}{DOWN}{DOWN}{y}\r"),
            &format!("centre y (m) = {y}"),
        );
        // Past the centre's latitude and longitude (empty without an origin).
        step(&mut s, &format!("{DOWN}{DOWN}{DOWN}2\r"), "radius (m) = 2");
        step(&mut s, &format!("{DOWN}60\r"), "height (m) = 60");
        step(
            &mut s,
            &format!("{DOWN}\r\x15yes\r"),
            "inspect (eq. 8) = yes",
        );
    }
    // Four UAVs in a diamond, in the formation editor.
    step(&mut s, "\t2", "Formation · 3 UAVs");
    step(&mut s, "\t\t", "Inspector · Formation");
    step(&mut s, "4\r", "UAVs = 4");
    step(
        &mut s,
        &format!("{DOWN}\r\x15diamond\r"),
        "preset = diamond",
    );
    step(&mut s, "\x13", "saved"); // Ctrl-s
    s.send("q");
    assert_eq!(s.wait_exit(Duration::from_secs(20)), 0);

    let text = std::fs::read_to_string(&file).unwrap();
    assert!(
        !text.lines().any(|l| l.trim_start().starts_with("[origin]")),
        "{text}"
    );
    for other in ["bridge", "pier", "light pole", "ΔT", "eq. 8", "Sydney"] {
        assert!(!text.contains(other), "'{other}' in the new file:\n{text}");
    }
    let m = mission::load(&file).unwrap().mission;
    assert!(m.origin.is_none(), "{text}");
    assert_eq!(m.name, "turbines");
    assert_eq!(m.bounds.x, [0.0, 200.0]);
    assert_eq!(m.bounds.y, [0.0, 150.0]);
    assert_eq!(m.bounds.z, [20.0, 40.0]);
    assert_eq!(m.route.start, nalgebra::Point3::new(10.0, 75.0, 30.0));
    assert_eq!(m.route.goal, nalgebra::Point3::new(190.0, 75.0, 30.0));
    let towers: Vec<_> = m
        .obstacles
        .iter()
        .map(|o| (o.name.as_str(), o.center.x, o.center.y, o.radius, o.inspect))
        .collect();
    assert_eq!(
        towers,
        [
            ("tower 1", 100.0, 69.0, 2.0, true),
            ("tower 2", 100.0, 81.0, 2.0, true)
        ]
    );
    // A diamond: one ahead, one behind, one each side, at one distance
    // from the centroid, written to the millimetre.
    let slots = &m.formation.slots;
    assert_eq!(slots.len(), 4, "{text}");
    let r = slots[0].norm();
    for slot in slots {
        assert!((slot.norm() - r).abs() < 1e-9, "{slots:?}");
        assert!(slot.x == 0.0 || slot.y == 0.0, "{slots:?}");
        for v in slot.iter() {
            assert_eq!((v * 1000.0).round() / 1000.0, *v, "{slots:?}");
        }
    }
}

/// The agent processes of a distributed fleet: skyform processes whose
/// command line runs `agent`.
fn agent_processes() -> Vec<u32> {
    let Ok(entries) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    entries
        .filter_map(|e| e.ok()?.file_name().to_str()?.parse::<u32>().ok())
        .filter(|pid| {
            let cmdline = std::fs::read(format!("/proc/{pid}/cmdline")).unwrap_or_default();
            let args: Vec<&[u8]> = cmdline.split(|&b| b == 0).collect();
            let zombie = std::fs::read_to_string(format!("/proc/{pid}/stat"))
                .is_ok_and(|s| s.rsplit_once(") ").is_some_and(|(_, r)| r.starts_with('Z')));
            !zombie
                && args.first().is_some_and(|a| a.ends_with(b"skyform"))
                && args.get(1) == Some(&&b"agent"[..])
        })
        .collect()
}

/// `Z` flies the fleet with its agents in processes of their own: the job
/// shows its agents alive while it runs and its processes in the result,
/// the verdict is the in-process one, and no agent process is left.
#[cfg(feature = "zenoh")]
#[test]
fn z_runs_the_fleet_over_agent_processes() {
    let dir = tempfile::tempdir().unwrap();
    let state = dir.path().join("state");
    let file = dir.path().join("fleet.toml");
    let mut m = mission::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/missions/fleet-triangle.toml"
    )))
    .unwrap()
    .mission;
    m.fleet.duration = Some(14.0);
    m.fleet.targets.truncate(1);
    std::fs::write(&file, mission::to_toml_string(&m).unwrap()).unwrap();
    let mut s = launch(&file, &state);
    s.wait_for("Inspector", Duration::from_secs(20));
    s.send("Z");
    s.wait_for("agent process(es) over Zenoh", Duration::from_secs(30));
    s.wait_for("⇄3/3", Duration::from_secs(30));
    s.wait_for(
        "3 agent process(es) over Zenoh, lockstep",
        Duration::from_secs(60),
    );
    s.wait_for("pass ⇄3/3", Duration::from_secs(5));
    s.send("q");
    assert_eq!(s.wait_exit(Duration::from_secs(10)), 0);
    let deadline = Instant::now() + Duration::from_secs(10);
    while !agent_processes().is_empty() && Instant::now() < deadline {
        thread::sleep(Duration::from_millis(50));
    }
    assert_eq!(agent_processes(), Vec::<u32>::new(), "agent processes left");
}

/// The process's CPU time so far (user + system), in clock ticks.
fn cpu_ticks(pid: u32) -> u64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    let rest = stat.rsplit_once(") ").map(|(_, r)| r).unwrap();
    let fields: Vec<&str> = rest.split_whitespace().collect();
    // utime and stime are fields 14 and 15 of stat, 12 and 13 after ") ".
    fields[11].parse::<u64>().unwrap() + fields[12].parse::<u64>().unwrap()
}

/// The live plan's J as the jobs panel shows it ("J 172.65 · …").
fn shown_cost(s: &Session) -> Option<String> {
    s.contents().lines().find_map(|l| {
        l.split("││")
            .nth(1)?
            .trim_start()
            .strip_prefix("J ")
            .map(|r| r.split_whitespace().next().unwrap_or("").to_owned())
    })
}

/// Live planning in a real terminal: the bridge is planned as it opens;
/// tree 9 moved onto the route bends the plan (another J), which stays
/// feasible; once nothing changes the designer uses no CPU; with --no-live
/// nothing runs until asked.
#[test]
fn the_plan_follows_an_obstacle_moved_across_it_and_idles_after() {
    let dir = tempfile::tempdir().unwrap();
    let file = bridge_copy(dir.path());
    let mut s = launch(&file, &dir.path().join("state"));
    s.wait_for("live 1", Duration::from_secs(30));
    s.wait_for("feasible", Duration::from_secs(30));
    s.wait_for("FEASIBLE", Duration::from_secs(10));
    let before = shown_cost(&s).expect("the live plan's J");
    // Tree 9 is the twelfth item (mission, bounds, start, goal, 8 obstacles).
    for _ in 0..11 {
        s.send("n");
    }
    s.wait_for("'tree 9'", Duration::from_secs(5));
    for _ in 0..6 {
        s.send("\x1b[B"); // Down: 1 m south, onto the route
        thread::sleep(Duration::from_millis(30));
    }
    let deadline = Instant::now() + Duration::from_secs(30);
    while (s.contents().contains("re-planning") || shown_cost(&s).as_deref() == Some(&before))
        && Instant::now() < deadline
    {
        thread::sleep(Duration::from_millis(50));
    }
    let after = shown_cost(&s).expect("the new plan's J");
    assert_ne!(
        after,
        before,
        "the plan changed; the screen:\n{}",
        s.contents()
    );
    assert!(s.contents().contains("✓ FEASIBLE"), "{}", s.contents());
    // Idle: nothing changes, nothing runs, no CPU. A second first for the
    // finished run's threads to wind down (on a loaded machine that work
    // is late, not more).
    let pid = s.child.process_id().unwrap();
    thread::sleep(Duration::from_secs(1));
    let used = cpu_ticks(pid);
    thread::sleep(Duration::from_secs(3));
    let idle = cpu_ticks(pid) - used;
    assert!(idle <= 2, "{idle} ticks of CPU in 3 s idle");
    s.send("q");
    s.wait_for("unsaved", Duration::from_secs(5));
    s.send("y");
    assert_eq!(s.wait_exit(Duration::from_secs(10)), 0);

    // --no-live: the designer as before, nothing planned until r.
    let mut s = launch_with(
        &file,
        &dir.path().join("state2"),
        ROWS,
        COLS,
        &["--no-live"],
    );
    s.wait_for("No runs yet", Duration::from_secs(20));
    thread::sleep(Duration::from_millis(500));
    assert!(!s.contents().contains("live 1"), "{}", s.contents());
    s.send("q");
    assert_eq!(s.wait_exit(Duration::from_secs(10)), 0);
}

/// Issue 36, item 7, in a real terminal at 80 × 24: a 221-obstacle site
/// opens with live planning off and says why (the obstacles over live
/// planning's 200) and that `L` turns it on; `/` finds a mast by name,
/// selects it and the map draws its name; `L` plans live anyway.
#[test]
fn a_221_obstacle_site_says_why_live_is_off_and_finds_a_mast_at_80_by_24() {
    let dir = tempfile::tempdir().unwrap();
    let state = tempfile::tempdir().unwrap();
    let file = dir.path().join("site.toml");
    let mut m = skyform::tui::fixtures::bridge_with_oak_rows(11);
    m.theta_pso.swarm_size = 20;
    m.theta_pso.iterations = 10;
    std::fs::write(&file, mission::to_toml_string(&m).unwrap()).unwrap();
    let mut s = launch_sized(&file, state.path(), 24, 80);
    s.wait_for(
        "live planning off: 221 obstacles (live up to 200); L turns it on",
        Duration::from_secs(30),
    );
    assert!(!s.contents().contains("live 1"), "{}", s.contents());
    step(&mut s, "/", "type part of an obstacle");
    step(&mut s, "mast 2", "1 of 1: Obstacle 220 'mast 2'");
    step(
        &mut s,
        "\r",
        "Obstacle 220 'mast 2': the one match for 'mast 2'",
    );
    // Its name on the map's canvas (not only on the status line and the
    // map's bottom line).
    let screen = s.contents();
    assert!(
        screen
            .lines()
            .skip(1)
            .take(21)
            .any(|l| l.contains("mast 2")),
        "{screen}"
    );
    step(
        &mut s,
        "L",
        "live planning on: 221 obstacles (live up to 200)",
    );
    s.wait_for("live 1", Duration::from_secs(300));
    s.send("q");
    assert_eq!(s.wait_exit(Duration::from_secs(20)), 0);
}

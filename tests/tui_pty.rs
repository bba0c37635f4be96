//! End to end: the real binary in a pseudo-terminal, driven by keystrokes,
//! its screen read back through a terminal emulator (vt100). Opens a copy of
//! a mission, adds an obstacle, runs θ-PSO to the end, saves and quits; then
//! checks the saved file and that the terminal is back in cooked mode.

#![cfg(unix)]

use std::io::{Read, Write};
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::{Duration, Instant};

use portable_pty::{CommandBuilder, MasterPty, PtySize, native_pty_system};
use skyform::mission;

const ROWS: u16 = 40;
const COLS: u16 = 130;

struct Session {
    master: Box<dyn MasterPty + Send>,
    writer: Box<dyn Write + Send>,
    screen: Arc<Mutex<vt100::Parser>>,
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

#[test]
fn edit_run_save_quit_in_a_real_terminal() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bridge.toml");
    std::fs::copy(
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/missions/bridge-inspection.toml"
        ),
        &file,
    )
    .unwrap();
    let before = mission::load(&file).unwrap().mission;

    let pair = native_pty_system()
        .openpty(PtySize {
            rows: ROWS,
            cols: COLS,
            pixel_width: 0,
            pixel_height: 0,
        })
        .unwrap();
    let cooked =
        |flags: &[String]| flags.iter().any(|f| f == "ICANON") && flags.iter().any(|f| f == "ECHO");

    let mut cmd = CommandBuilder::new(env!("CARGO_BIN_EXE_skyform"));
    cmd.arg(&file);
    cmd.cwd(dir.path());
    cmd.env("TERM", "xterm-256color");
    let mut child = pair.slave.spawn_command(cmd).unwrap();
    drop(pair.slave);

    let screen = Arc::new(Mutex::new(vt100::Parser::new(
        std::num::NonZero::new(ROWS).unwrap(),
        std::num::NonZero::new(COLS).unwrap(),
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
    let mut s = Session {
        master: pair.master,
        writer,
        screen,
    };

    s.wait_for("Inspector", Duration::from_secs(30));
    s.wait_for("bridge.toml", Duration::from_secs(5));
    assert!(
        !cooked(&s.local_flags()),
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
    let deadline = Instant::now() + Duration::from_secs(20);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        assert!(
            Instant::now() < deadline,
            "skyform did not quit; the screen:\n{}",
            s.contents()
        );
        thread::sleep(Duration::from_millis(50));
    };
    assert!(status.success(), "exit status {status:?}");
    assert!(
        cooked(&s.local_flags()),
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
}

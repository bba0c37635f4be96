//! Zenoh sessions as the fleet uses them: the coordinator's hub (a router
//! listening on one TCP endpoint) and the agents' clients connected to it.
//! No scouting of any kind (a run finds its peers by the endpoint it is
//! given, never by multicast), a one-second lease so a process that hangs
//! is noticed, TCP only.

use std::time::Duration;

use zenoh::{Config, Session, Wait};

/// Longest wait for a session to open.
const OPEN_TIMEOUT_MS: u64 = 10_000;

fn base(mode: &str) -> Result<Config, String> {
    let mut c = Config::default();
    let mut set = |key: &str, value: &str| {
        c.insert_json5(key, value)
            .map_err(|e| format!("zenoh config {key} = {value}: {e}"))
    };
    set("mode", &format!("\"{mode}\""))?;
    set("scouting/multicast/enabled", "false")?;
    set("scouting/gossip/enabled", "false")?;
    // A router waits this long for peers before it opens: none are coming.
    set("scouting/delay", "0")?;
    set("timestamping/enabled", "false")?;
    set("transport/link/tx/lease", "1000")?;
    set("transport/link/tx/keep_alive", "4")?;
    set(
        "transport/unicast/open_timeout",
        &OPEN_TIMEOUT_MS.to_string(),
    )?;
    Ok(c)
}

/// The coordinator's hub, listening on `endpoint` (`tcp/HOST:PORT`).
pub fn hub(endpoint: &str) -> Result<Session, String> {
    let mut c = base("router")?;
    c.insert_json5("listen/endpoints", &format!("[\"{endpoint}\"]"))
        .map_err(|e| format!("zenoh config listen/endpoints: {e}"))?;
    c.insert_json5("connect/endpoints", "[]")
        .map_err(|e| format!("zenoh config connect/endpoints: {e}"))?;
    zenoh::open(c)
        .wait()
        .map_err(|e| format!("cannot listen on {endpoint}: {e}"))
}

/// An agent process's client, connected to the hub at `endpoint`; tries
/// for up to `patience` while the hub is not yet listening.
pub fn client(endpoint: &str, patience: Duration) -> Result<Session, String> {
    let mut c = base("client")?;
    let mut set = |key: &str, value: &str| {
        c.insert_json5(key, value)
            .map_err(|e| format!("zenoh config {key}: {e}"))
    };
    set("connect/endpoints", &format!("[\"{endpoint}\"]"))?;
    set("listen/endpoints", "[]")?;
    set("connect/timeout_ms", &patience.as_millis().to_string())?;
    set(
        "connect/retry",
        "{ period_init_ms: 50, period_max_ms: 500, period_increase_factor: 2 }",
    )?;
    zenoh::open(c)
        .wait()
        .map_err(|e| format!("cannot reach the coordinator at {endpoint}: {e}"))
}

/// A TCP port free on 127.0.0.1 now (the system's choice): the hub listens
/// on it a moment later. Another process could take it in between; the
/// caller tries again on a failure to listen.
pub fn free_port() -> Result<u16, String> {
    let listener = std::net::TcpListener::bind("127.0.0.1:0")
        .map_err(|e| format!("no free TCP port on 127.0.0.1: {e}"))?;
    listener
        .local_addr()
        .map(|a| a.port())
        .map_err(|e| format!("no free TCP port on 127.0.0.1: {e}"))
}

/// A hub on a free port of 127.0.0.1: the session and its endpoint.
pub fn local_hub() -> Result<(Session, String), String> {
    let mut last = String::new();
    for _ in 0..5 {
        let endpoint = format!("tcp/127.0.0.1:{}", free_port()?);
        match hub(&endpoint) {
            Ok(s) => return Ok((s, endpoint)),
            Err(e) => last = e,
        }
    }
    Err(last)
}

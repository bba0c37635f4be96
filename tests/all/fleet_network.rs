//! The fleet's network model (`[fleet.network]`, issue 26): each agent
//! decides from the messages it heard, with latency and loss reproducible
//! from the seed, and the ideal network flies the fleet the paper simulates.

use skyform::mission::{self, FleetNetwork, FleetUpdate, Mission, Severity};
use skyform::pipelines::fleet::{self, FleetOutcome};
use skyform::pipelines::{CancelToken, Silent};

fn triangle_mission() -> Mission {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/missions/fleet-triangle.toml");
    mission::load(std::path::Path::new(path))
        .unwrap_or_else(|e| panic!("{e}"))
        .mission
}

/// The error loading the fleet triangle with `line` under `[fleet.network]`.
fn refusal(line: &str) -> String {
    let base = include_str!("../../missions/fleet-triangle.toml");
    let text = format!("{base}\n[fleet.network]\n{line}\n");
    match mission::parse_str(&text, "network.toml") {
        Ok(_) => panic!("{line} accepted"),
        Err(e) => e.to_string(),
    }
}

fn run(m: &Mission, seed: u64) -> FleetOutcome {
    let report = mission::validate(m);
    assert!(report.iter().all(|d| !d.is_error()), "{report:?}");
    fleet::plan(m, seed, &mut Silent, &CancelToken::new()).unwrap_or_else(|e| panic!("{e}"))
}

/// With no `[fleet.network]` every agent hears every neighbour's state of
/// this very step: the run is the one before the network existed, bit for
/// bit. The figures are those the snapshot-reading fleet gave for seed 3
/// (`skyform run fleet missions/fleet-triangle.toml --seed 3 --json`,
/// commit 3a490ec); a range of exactly l written out changes nothing.
#[test]
fn the_ideal_network_flies_the_fleet_of_the_perfect_snapshot_bit_for_bit() {
    let m = triangle_mission();
    assert!(m.fleet.network.is_ideal());
    let o = run(&m, 3);
    let closest = o.closest_agents.as_ref().map(|c| c.distance.to_bits());
    assert_eq!(closest, Some(1.124276646824256f64.to_bits()));
    let last = o.agents[1].samples.last().map(|s| s.position);
    let want = [2.452569341028794, -2.8916654882559207, 1.000009411727045];
    assert_eq!(
        last.map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]),
        Some(want.map(f64::to_bits))
    );
    // Every message arrived, none was lost, all of it fresh.
    for a in &o.agents {
        assert_eq!(a.network.lost, 0);
        assert!(a.network.received > 0 && a.network.worst_age == 0.0);
    }
    let mut explicit = m.clone();
    explicit.fleet.network.range = Some(m.fleet.neighbourhood);
    assert_eq!(run(&explicit, 3), o);
}

/// A network 0.1 s late that loses 30 % of the messages: the same seed
/// gives the same run (loss is a function of seed, sender, receiver and
/// step), the losses are counted at about the rate asked, and the agents
/// decided on information at least the latency old.
#[test]
fn a_late_lossy_network_is_reproducible_and_counted() {
    let mut m = triangle_mission();
    m.fleet.duration = Some(20.0);
    let latency = (0.1 / m.fleet.sim_step).round() as usize;
    m.fleet.network = FleetNetwork {
        range: None,
        latency,
        loss: 0.3,
        links: Vec::new(),
        updates: Vec::new(),
    };
    let (a, b) = (run(&m, 1), run(&m, 1));
    assert_eq!(a, b, "the same mission and seed fly the same");
    let (lost, received): (usize, usize) = a
        .agents
        .iter()
        .map(|x| (x.network.lost, x.network.received))
        .fold((0, 0), |s, x| (s.0 + x.0, s.1 + x.1));
    let rate = lost as f64 / (lost + received) as f64;
    assert!((rate - 0.3).abs() < 0.02, "lost {rate} of the messages");
    for x in &a.agents {
        assert!(x.network.mean_age >= 0.1 - 1e-9, "{:?}", x.network);
        assert!(x.network.worst_age >= x.network.mean_age);
    }
    let mut ideal = m.clone();
    ideal.fleet.network = FleetNetwork::default();
    let perfect = run(&ideal, 1);
    assert_ne!(
        perfect.agents[0].samples, a.agents[0].samples,
        "late, lossy information changes the flight"
    );
}

/// A loss of 1 would lose every message, and a latency longer than the run
/// would deliver none: both are refused naming the field.
#[test]
fn an_impossible_network_is_refused_naming_the_field() {
    let mut m = triangle_mission();
    m.fleet.network.loss = 1.0;
    m.fleet.network.latency = 1_000_000;
    let report = mission::validate(&m);
    let at = |path: &str| {
        report
            .iter()
            .find(|d| d.severity == Severity::Error && d.path.to_string() == path)
            .map(|d| d.message.clone())
    };
    let loss = at("fleet.network.loss").unwrap_or_default();
    assert!(loss.contains("[0, 1)"), "{loss}");
    let late = at("fleet.network.latency").unwrap_or_default();
    assert!(late.contains("longer than the whole run"), "{late}");
}

/// A link of its own (agents 1 and 3, 60 steps: 0.3 s) is written in the
/// mission and flies differently from the default latency; a link naming an
/// agent the fleet does not have, or given twice, is refused naming it.
#[test]
fn a_link_with_a_latency_of_its_own_is_read_checked_and_flown() {
    let base = include_str!("../../missions/fleet-triangle.toml");
    let text = format!(
        "{base}\n[fleet.network]\nlatency = 1\nlinks = [{{ between = [1, 3], latency = 60 }}]\n"
    );
    let mut m = skyform::mission::parse_str(&text, "links.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    assert_eq!(m.fleet.network.links[0].between, [1, 3]);
    m.fleet.duration = Some(20.0);
    let linked = run(&m, 2);
    m.fleet.network.links.clear();
    let plain = run(&m, 2);
    assert_ne!(linked.agents[0].samples, plain.agents[0].samples);
    // Agent 1 heard agent 3 0.3 s late at worst, agent 2 (the default link) 5 ms.
    assert!(
        linked.agents[0].network.worst_age >= 0.3 - 1e-9,
        "{:?}",
        linked.agents[0].network
    );
    assert!(
        linked.agents[1].network.worst_age < 0.1,
        "{:?}",
        linked.agents[1].network
    );
    for (links, wanted) in [
        ("[{ between = [1, 4], latency = 2 }]", "from 1 to 3"),
        (
            "[{ between = [1, 2], latency = 2 }, { between = [2, 1], latency = 3 }]",
            "twice",
        ),
    ] {
        let err = refusal(&format!("links = {links}"));
        assert!(
            err.contains("fleet.network.links") && err.contains(wanted),
            "{err}"
        );
    }
}

/// Asynchronous agents (`[fleet.network] updates`): agent 2 on a clock of
/// its own (every 60 steps from step 7, three rounds of τ) decides at its own
/// steps, well under half as often as the others; the same seed repeats; on
/// τ's own period and phase 0 it is the fleet's run bit for bit; a clock
/// that names no agent, never ticks or starts past its period is refused
/// naming the field.
#[test]
fn agents_on_their_own_clocks_decide_on_them_and_repeat() {
    let base = include_str!("../../missions/fleet-triangle.toml");
    let text =
        format!("{base}\n[fleet.network]\nupdates = [{{ agent = 2, period = 60, phase = 7 }}]\n");
    let mut m = skyform::mission::parse_str(&text, "clocks.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .mission;
    assert_eq!(
        m.fleet.network.updates,
        vec![FleetUpdate {
            agent: 2,
            period: 60,
            phase: 7
        }]
    );
    m.fleet.duration = Some(20.0);
    let own = run(&m, 4);
    assert_eq!(own, run(&m, 4), "the same mission and seed fly the same");
    let steps = (m.fleet.duration.unwrap_or(0.0) / m.fleet.sim_step).round() as usize;
    // Its own steps 7, 67, …: each one a decision (the first target is out
    // from t = 0); a neighbour closer than c may add some.
    let ticks = (steps - 7) / 60 + 1;
    let (first, second) = (own.agents[0].decisions, own.agents[1].decisions);
    assert!(
        second >= ticks && 2 * second < first,
        "agent 2 decided {second} times on {ticks} ticks, agent 1 {first} times"
    );
    // The summary says who decided how often.
    let summary = skyform::outcome::Outcome::Fleet(Box::new(own.clone())).summary();
    assert!(
        summary.contains(&format!(
            "({first} / {second} / {} by agent)",
            own.agents[2].decisions
        )),
        "{summary}"
    );
    let mut plain = m.clone();
    plain.fleet.network.updates.clear();
    let plain_run = run(&plain, 4);
    assert_ne!(own.agents[1].samples, plain_run.agents[1].samples);
    let round = (m.fleet.replan_period / m.fleet.sim_step).round() as usize;
    m.fleet.network.updates[0] = FleetUpdate {
        agent: 2,
        period: round,
        phase: 0,
    };
    assert_eq!(run(&m, 4), plain_run, "τ's own clock is the fleet's");

    for (updates, field, wanted) in [
        ("[{ agent = 4, period = 20 }]", "agent", "from 1 to 3"),
        ("[{ agent = 1, period = 0 }]", "period", "at least 1 step"),
        (
            "[{ agent = 1, period = 20, phase = 20 }]",
            "phase",
            "below the period",
        ),
        (
            "[{ agent = 1, period = 20 }, { agent = 1, period = 30 }]",
            "agent",
            "twice",
        ),
    ] {
        let err = refusal(&format!("updates = {updates}"));
        assert!(
            err.contains("fleet.network.updates") && err.contains(field) && err.contains(wanted),
            "{err}"
        );
    }
}

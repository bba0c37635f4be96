//! Fuzzing the loader (issue 12): generated and mutated mission files through
//! load, validation, the pipelines' findings and their budgets
//! (`diagnose::check_text`, what `check`, `run` and the designer call).
//! Whatever the text: no panic, and either a mission or an error.
//!
//! CI runs 2,000 cases per property; the long run, by hand:
//!
//! ```text
//! SKYFORM_FUZZ_CASES=50000 cargo test --release --test all fuzz_loader::
//! ```
//! (two properties: 10^5 files in all).

use proptest::prelude::*;
use proptest::test_runner::TestCaseError;
use skyform::mission::BUILTIN;

fn cases() -> u32 {
    std::env::var("SKYFORM_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2_000)
}

/// Values that break things: extremes, non-numbers, wrong types.
const TOKENS: &[&str] = &[
    "0",
    "-1",
    "1e-9",
    "1e9",
    "1e300",
    "-1e300",
    "nan",
    "inf",
    "-inf",
    "-0.0",
    "2147483648",
    "9223372036854775807",
    "99999999999999999999",
    "0.000001",
    "\"text\"",
    "true",
    "[]",
    "[1, 2]",
    "[[0.0, 0.0, 0.0]]",
    "{}",
    "1979-05-27",
];

/// Keys the model knows, to put in the wrong place.
const KEYS: &[&str] = &[
    "swarm_size",
    "iterations",
    "restarts",
    "aircraft",
    "agents",
    "ground_speed",
    "sim_step",
    "duration",
    "spacing",
    "radius",
    "center",
    "slots",
    "between",
    "scale",
    "x",
    "z",
    "seeded_particles",
    "segments",
    "waypoints",
    "replan_period",
    "sample_period",
];

#[derive(Debug, Clone)]
enum Mutation {
    /// Replace the n-th number of the text with a token.
    Number(usize, &'static str),
    /// Add `key = token` after line n.
    Insert(usize, &'static str, &'static str),
    DeleteLine(usize),
    DuplicateLine(usize),
    /// Bytes spliced in at a char position.
    Splice(usize, String),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        4 => (0usize..400, proptest::sample::select(TOKENS)).prop_map(|(n, t)| Mutation::Number(n, t)),
        2 => (0usize..200, proptest::sample::select(KEYS), proptest::sample::select(TOKENS))
            .prop_map(|(n, k, t)| Mutation::Insert(n, k, t)),
        1 => (0usize..200).prop_map(Mutation::DeleteLine),
        1 => (0usize..200).prop_map(Mutation::DuplicateLine),
        1 => (0usize..6000, "[\\[\\]=\"a-z0-9._, \n-]{0,6}").prop_map(|(n, s)| Mutation::Splice(n, s)),
    ]
}

fn apply(text: &str, m: &Mutation) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let n_lines = lines.len().max(1);
    match m {
        Mutation::Number(n, token) => {
            // Numbers as TOML writes them in the shipped files.
            let mut starts = Vec::new();
            let bytes = text.as_bytes();
            let mut i = 0;
            while i < bytes.len() {
                let starts_number = (bytes[i].is_ascii_digit() || bytes[i] == b'-')
                    && (i == 0 || matches!(bytes[i - 1], b' ' | b'[' | b','));
                if starts_number {
                    let mut j = i + 1;
                    while j < bytes.len()
                        && (bytes[j].is_ascii_digit() || matches!(bytes[j], b'.' | b'e' | b'-'))
                    {
                        j += 1;
                    }
                    starts.push((i, j));
                    i = j;
                } else {
                    i += 1;
                }
            }
            match starts.get(n % starts.len().max(1)) {
                Some(&(a, b)) => format!("{}{}{}", &text[..a], token, &text[b..]),
                None => text.to_owned(),
            }
        }
        Mutation::Insert(n, key, token) => {
            let at = n % n_lines;
            let mut out: Vec<String> = lines.iter().map(|l| (*l).to_owned()).collect();
            out.insert((at + 1).min(out.len()), format!("{key} = {token}"));
            out.join("\n")
        }
        Mutation::DeleteLine(n) => {
            let at = n % n_lines;
            let mut out: Vec<&str> = lines.clone();
            if at < out.len() {
                out.remove(at);
            }
            out.join("\n")
        }
        Mutation::DuplicateLine(n) => {
            let at = n % n_lines;
            let mut out: Vec<&str> = lines.clone();
            if let Some(line) = out.get(at).copied() {
                out.insert(at, line);
            }
            out.join("\n")
        }
        Mutation::Splice(n, s) => {
            let cut = text
                .char_indices()
                .map(|(i, _)| i)
                .nth(n % text.chars().count().max(1))
                .unwrap_or(text.len());
            format!("{}{}{}", &text[..cut], s, &text[cut..])
        }
    }
}

/// Generated missions: a table of random known keys and random values.
fn generated() -> impl Strategy<Value = String> {
    let line = (
        proptest::sample::select(KEYS),
        proptest::sample::select(TOKENS),
    )
        .prop_map(|(k, t)| format!("{k} = {t}"));
    let section = (
        proptest::sample::select(
            &[
                "bounds",
                "route",
                "formation",
                "reconfiguration",
                "theta_pso",
                "flatlo",
                "fleet",
                "[obstacles]",
                "[reconfiguration.waypoints]",
            ][..],
        ),
        proptest::collection::vec(line, 0..6),
    )
        .prop_map(|(name, lines)| format!("[{name}]\n{}\n", lines.join("\n")));
    proptest::collection::vec(section, 0..6)
        .prop_map(|sections| format!("name = \"fuzz\"\n{}", sections.join("\n")))
}

fn check(text: &str) -> Result<(), TestCaseError> {
    let checked = skyform::outcome::diagnose::check_text(text, Some("fuzz.toml"));
    prop_assert!(checked.mission.is_some() || checked.report.has_errors());
    // Every error names where it is.
    for d in checked.report.errors() {
        prop_assert!(!d.message.is_empty());
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn mutated_shipped_missions_are_checked_without_panic(
        which in 0usize..BUILTIN.len(),
        mutations in proptest::collection::vec(mutation(), 1..5),
    ) {
        let mut text = BUILTIN[which].text.to_owned();
        for m in &mutations {
            text = apply(&text, m);
        }
        check(&text)?;
    }

    #[test]
    fn generated_missions_are_checked_without_panic(text in generated()) {
        check(&text)?;
    }
}

//! Issue 52, items 1-2: the rare-event estimate (subset simulation) agrees
//! with brute force where brute force resolves the answer, and is the same
//! on any number of threads.

use skyform::export::Planned;
use skyform::flight::rare::{self, Limit, RareOptions};
use skyform::flight::{self, Setup};
use skyform::mission::{self, Mission};
use skyform::outcome;
use skyform::pipelines::theta_pso::PlanOptions;
use skyform::pipelines::{CancelToken, Kind, Silent};

/// The bridge in its shipped wind and turbulence on better fixes (GNSS σ
/// 0.3 m): about 2.5 % of flights break 2 r_Q, 73 % r_Q (2,000 flights).
fn bridge(margin: f64) -> Mission {
    let mut m = mission::default_mission().mission;
    m.flight.gnss_sigma_horizontal = 0.3;
    m.formation.obstacle_margin = margin;
    m
}

fn planned(m: &Mission) -> Planned {
    let o = outcome::run(
        Kind::ThetaPso,
        m,
        1,
        PlanOptions::default(),
        &mut Silent,
        &CancelToken::new(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    Planned::from_outcome(m, &o)
}

fn estimate(setup: &Setup, limit: Limit, per_level: usize, threads: usize) -> rare::Estimate {
    let options = RareOptions {
        per_level,
        seed: 3,
        threads: Some(threads),
    };
    rare::estimate(setup, limit, options, &|_, _| {}, &CancelToken::new())
        .unwrap_or_else(|e| panic!("{e}"))
}

/// Item 2: on two limits of two weathers of the bridge (shares 10⁻²-10⁻¹),
/// the estimate's 95 % interval and brute force's Wilson interval over
/// 2,000 flights overlap, and the estimate is within a factor 2.
#[test]
fn the_estimate_agrees_with_brute_force_where_it_resolves_the_answer() {
    for (margin, limit) in [(0.0, Limit::Separation), (0.3, Limit::Clearance)] {
        let m = bridge(margin);
        let planned = planned(&m);
        let setup = Setup::new(&m, &planned).unwrap_or_else(|e| panic!("{e}"));
        let options = flight::Options {
            flights: 2000,
            seed: 1,
            threads: None,
        };
        let report = flight::check(&setup, options, &|_, _| {}, &CancelToken::new())
            .unwrap_or_else(|e| panic!("{e}"));
        let brute = match limit {
            Limit::Separation => &report.break_separation,
            Limit::Clearance => &report.break_clearance,
        };
        let (share, low, high) = (brute.share, brute.low, brute.high);
        let e = estimate(&setup, limit, 400, 2);
        eprintln!(
            "{limit:?} at margin {margin}: brute force {share:.4} ({low:.4}-{high:.4}), \
             subset simulation {:.4} ({:.4}-{:.4}, c.o.v. {:.2}, {} flights)",
            e.estimate, e.low, e.high, e.cov, e.flights
        );
        assert!(
            share > 0.005 && share < 0.2,
            "{limit:?}: {share}: not the case meant"
        );
        assert!(e.low <= high && low <= e.high, "{limit:?}: intervals apart");
        assert!(
            e.estimate > share / 2.0 && e.estimate < share * 2.0,
            "{limit:?}: {} vs {share}",
            e.estimate
        );
        assert_eq!(e.method, rare::METHOD);
        let f = e.most_likely.expect("a failing flight");
        assert!(f.room < 0.0, "{f:?}");
    }
}

/// Items 1-2: far below what 2,000 flights can show (the bridge 1.2 m
/// from its obstacles on σ 0.3 m fixes: no flight of 2,000 breaks r_Q),
/// the estimate goes down level by level to a probability under 10⁻³ with
/// its interval, and its most likely failing flight breaks r_Q when flown
/// again. The same on one thread or two.
#[test]
fn a_rare_break_is_estimated_level_by_level_the_same_on_any_thread_count() {
    let m = bridge(1.2);
    let planned = planned(&m);
    let setup = Setup::new(&m, &planned).unwrap_or_else(|e| panic!("{e}"));
    let one = estimate(&setup, Limit::Clearance, 200, 1);
    let two = estimate(&setup, Limit::Clearance, 200, 2);
    assert_eq!(one, two);
    eprintln!("{one:?}");
    assert!(!one.bound);
    assert!(one.levels.len() >= 3, "{:?}", one.levels);
    assert!(
        one.estimate < 1e-3 && one.estimate > 0.0,
        "{}",
        one.estimate
    );
    assert!(one.low < one.estimate && one.estimate < one.high);
    // The thresholds fall level by level to the limit itself.
    assert!(
        one.levels
            .windows(2)
            .all(|w| w[1].threshold < w[0].threshold),
        "{:?}",
        one.levels
    );
    assert_eq!(one.levels.last().map(|l| l.threshold), Some(0.0));
    let f = one.most_likely.expect("a failing flight");
    assert!(f.room < 0.0 && f.what.contains("from '"), "{f:?}");
}

//! The analytic friction and contact experiments as tests: each asserts every check of
//! one experiment (formula, expected value, tolerance and its reason live beside the
//! experiment in `tribo_scenes::validation`).

use tribo_scenes::validation::{self, Check};

fn assert_checks(checks: tribo::Result<Vec<Check>>) {
    let checks = checks.expect("experiment ran");
    assert!(!checks.is_empty(), "experiment produced no checks");
    let mut failed = Vec::new();
    for c in &checks {
        println!(
            "{:<20} {:<80} expected {:>12.6} measured {:>12.6} {:<5} {:?} {}",
            c.experiment,
            c.formula,
            c.expected,
            c.measured,
            c.unit,
            c.tolerance,
            if c.passed() { "ok" } else { "FAIL" }
        );
        if !c.passed() {
            failed.push(c.formula.clone());
        }
    }
    assert!(failed.is_empty(), "failed checks: {failed:#?}");
}

#[test]
fn incline_stick() {
    assert_checks(validation::incline_stick());
}

#[test]
fn incline_slide() {
    assert_checks(validation::incline_slide());
}

#[test]
fn incline_hysteresis() {
    assert_checks(validation::incline_hysteresis());
}

#[test]
fn slide_to_rest() {
    assert_checks(validation::slide_to_rest());
}

#[test]
fn pull() {
    assert_checks(validation::pull());
}

#[test]
fn slip_to_roll() {
    assert_checks(validation::slip_to_roll());
}

#[test]
fn rolling_resistance() {
    assert_checks(validation::rolling_resistance());
}

#[test]
fn restitution() {
    assert_checks(validation::restitution());
}

#[test]
fn conveyor() {
    assert_checks(validation::conveyor());
}

#[test]
fn combine_rules() {
    assert_checks(validation::combine_rules());
}

#[test]
fn stacking() {
    assert_checks(validation::stacking());
}

#[test]
fn mass_ratio() {
    assert_checks(validation::mass_ratio());
}

#[test]
fn conservation() {
    assert_checks(validation::conservation());
}

#[test]
fn mass_ratio_slope() {
    assert_checks(validation::mass_ratio_slope());
}

//! Smoke run of the benchmark program: a few steps of every scene (and of the smallest
//! scaling scene) for every engine, one run.
//! It checks that the program works and that its JSON records have the promised fields;
//! it asserts no timings (speed is measured by running the program, see bench/RESULTS.md).

use std::process::Command;

/// Fields every JSON record has (the list).
const FIELDS: [&str; 6] = [
    "threads",
    "runs",
    "steps",
    "ms_per_step_median",
    "ms_per_step_min",
    "check_passed",
];

/// Runs the benchmark program with `args` (plus JSON on stdout); returns stdout and the
/// parsed records.
fn run(args: &[&str]) -> (String, Vec<serde_json::Value>) {
    let out = Command::new(env!("CARGO_BIN_EXE_tribo-bench"))
        .args(args)
        .args(["--json", "-"])
        .output()
        .expect("tribo-bench runs");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    let records = stdout
        .lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| serde_json::from_str(l).expect("json record"))
        .collect();
    (stdout, records)
}

/// The record of `scene` and `engine`, with every field of `fields` present.
fn record<'a>(
    records: &'a [serde_json::Value],
    stdout: &str,
    scene: &str,
    engine: &str,
    fields: &[&str],
) -> &'a serde_json::Value {
    let r = records
        .iter()
        .find(|r| r["scene"] == scene && r["engine"] == engine)
        .unwrap_or_else(|| panic!("no record for {scene}/{engine} in:\n{stdout}"));
    for field in fields {
        assert!(!r[*field].is_null(), "{scene}/{engine}: missing {field}");
    }
    r
}

#[test]
fn every_scene_runs_for_every_engine() {
    let (stdout, records) = run(&["all", "--runs", "1", "--steps", "3"]);
    for scene in [
        "large_pyramid",
        "many_pyramids",
        "smash",
        "tumbler",
        "compounds",
        "junkyard",
        "joint_grid",
        "spinner",
        "rain",
        "washer",
    ] {
        for engine in ["tribo", "box2d", "rapier"] {
            let r = record(&records, &stdout, scene, engine, &FIELDS);
            assert!(r["ms_per_step_median"]
                .as_f64()
                .is_some_and(|v| v.is_finite() && v >= 0.0));
        }
    }
}

#[test]
fn smallest_scaling_scene_runs_for_every_engine() {
    let (stdout, records) = run(&["scaling", "--sizes", "1000", "--runs", "1", "--steps", "3"]);
    assert!(stdout.contains("== scaling:"), "no scaling table in:\n{stdout}");
    for engine in ["tribo", "box2d", "rapier"] {
        let fields = [FIELDS.as_slice(), &["bodies", "us_per_step_per_body_median"]].concat();
        let r = record(&records, &stdout, "scaling_rain_1000", engine, &fields);
        assert_eq!(r["dynamic_bodies"], 1000);
        assert_eq!(r["check_passed"], true, "{engine}: {}", r["check"]);
    }
}

#[test]
fn two_threads_also_time_one_thread_in_the_same_run() {
    let (stdout, records) = run(&[
        "large_pyramid",
        "--runs",
        "1",
        "--steps",
        "3",
        "--threads",
        "2",
        "--no-friction-table",
    ]);
    assert!(stdout.contains("== thread scaling"), "no thread table in:\n{stdout}");
    for engine in ["tribo", "box2d"] {
        for threads in [1, 2] {
            let found = records
                .iter()
                .any(|r| r["scene"] == "large_pyramid" && r["engine"] == engine && r["threads"] == threads);
            assert!(found, "no {engine} record on {threads} thread(s) in:\n{stdout}");
        }
    }
}

/// Rain through its first re-creation: by step 312 all 40 columns exist (11 000 ragdoll
/// bodies), at step 320 the hook destroys column 0 and creates it again, so each engine
/// must still hold exactly 40 × 275 bodies, none through a shelf.
#[test]
fn rain_hook_creates_and_destroys_ragdolls_in_every_engine() {
    let (stdout, records) = run(&["rain", "--runs", "1", "--steps", "330", "--no-friction-table"]);
    for engine in ["tribo", "box2d", "rapier"] {
        let r = record(&records, &stdout, "rain", engine, &FIELDS);
        assert_eq!(r["check"]["bodies"], 11_000, "{engine}: {}", r["check"]);
        assert_eq!(r["check_passed"], true, "{engine}: {}", r["check"]);
    }
}

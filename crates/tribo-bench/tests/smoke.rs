//! Smoke run of the benchmark program: a few steps of every scene (and of the smallest
//! scaling scene) for every engine, one run.
//! It checks that the program works and that its JSON records have the promised fields;
//! it asserts no timings (speed is measured by running the program, see bench/RESULTS.md).

use std::process::Command;

#[test]
fn every_scene_runs_for_every_engine() {
    let out = Command::new(env!("CARGO_BIN_EXE_tribo-bench"))
        .args(["all", "--runs", "1", "--steps", "3", "--json", "-"])
        .output()
        .expect("tribo-bench runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    let records: Vec<serde_json::Value> = stdout
        .lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| serde_json::from_str(l).expect("json record"))
        .collect();
    for scene in ["large_pyramid", "many_pyramids", "smash", "tumbler"] {
        for engine in ["tribo", "box2d", "rapier"] {
            let r = records
                .iter()
                .find(|r| r["scene"] == scene && r["engine"] == engine)
                .unwrap_or_else(|| panic!("no record for {scene}/{engine} in:\n{stdout}"));
            for field in [
                "threads",
                "runs",
                "steps",
                "ms_per_step_median",
                "ms_per_step_min",
                "check_passed",
            ] {
                assert!(!r[field].is_null(), "{scene}/{engine}: missing {field}");
            }
            assert!(r["ms_per_step_median"]
                .as_f64()
                .is_some_and(|v| v.is_finite() && v >= 0.0));
        }
    }
}

#[test]
fn smallest_scaling_scene_runs_for_every_engine() {
    let out = Command::new(env!("CARGO_BIN_EXE_tribo-bench"))
        .args([
            "scaling", "--sizes", "1000", "--runs", "1", "--steps", "3", "--json", "-",
        ])
        .output()
        .expect("tribo-bench runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(stdout.contains("== scaling:"), "no scaling table in:\n{stdout}");
    let records: Vec<serde_json::Value> = stdout
        .lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| serde_json::from_str(l).expect("json record"))
        .collect();
    for engine in ["tribo", "box2d", "rapier"] {
        let r = records
            .iter()
            .find(|r| r["scene"] == "scaling_rain_1000" && r["engine"] == engine)
            .unwrap_or_else(|| panic!("no record for scaling_rain_1000/{engine} in:\n{stdout}"));
        for field in [
            "threads",
            "runs",
            "steps",
            "ms_per_step_median",
            "ms_per_step_min",
            "check_passed",
            "bodies",
            "us_per_step_per_body_median",
        ] {
            assert!(!r[field].is_null(), "{engine}: missing {field}");
        }
        assert_eq!(r["dynamic_bodies"], 1000);
        assert_eq!(r["check_passed"], true, "{engine}: {}", r["check"]);
    }
}

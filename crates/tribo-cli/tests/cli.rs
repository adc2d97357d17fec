//! The `tribo` command end to end: each subcommand, output formats read back, pictures
//! decoded, export → run round trip, and a table of malformed scene files.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tribo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tribo"))
        .args(args)
        .output()
        .expect("tribo runs")
}

fn tmp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tribo-cli-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

#[test]
fn scenes_lists_every_builtin() {
    let out = tribo(&["scenes"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for name in [
        "incline",
        "friction_ramp",
        "pyramid",
        "card_house",
        "dominoes",
        "rolling",
        "bounce",
        "conveyor",
        "tumbler",
        "large_pyramid",
        "many_pyramids",
        "rain",
        "ragdolls",
    ] {
        assert!(
            text.lines().any(|l| l.starts_with(name)),
            "{name} missing from:\n{text}"
        );
    }
}

/// Reads a trajectory CSV into (step, body, x, y, vx) rows.
fn read_csv(path: &Path) -> Vec<(u32, String, f64, f64, f64)> {
    let text = std::fs::read_to_string(path).expect("csv");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("step,time,body,x,y,angle,vx,vy,omega"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 9, "{l}");
            (
                f[0].parse().expect("step"),
                f[2].to_string(),
                f[3].parse().expect("x"),
                f[4].parse().expect("y"),
                f[6].parse().expect("vx"),
            )
        })
        .collect()
}

#[test]
fn run_writes_a_trajectory_that_shows_the_friction_physics() {
    let dir = tmp_dir("traj");
    let csv = dir.join("t.csv");
    let out = tribo(&["run", "incline", "--steps", "60", "--out", s(&csv)]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let rows = read_csv(&csv);
    // 4 bodies (slope + 3 blocks) × 61 records (step 0 and 60 steps).
    assert_eq!(rows.len(), 4 * 61);
    let track = |name: &str| -> Vec<(f64, f64)> { rows.iter().filter(|r| r.1 == name).map(|r| (r.2, r.3)).collect() };
    // μd < tan θ = 0.5 < μs: the block released at rest holds (< 0.05 mm in 1 s) …
    let rest = track("at_rest");
    let d = ((rest[60].0 - rest[0].0).powi(2) + (rest[60].1 - rest[0].1).powi(2)).sqrt();
    assert!(d < 5e-5, "at_rest moved {d} m");
    // … while the pushed one keeps sliding: a = g (sin θ − μd cos θ) = 0.877 m/s², so in 1 s
    // it covers 1.5·1 + 0.877/2 = 1.94 m (within 5 %: sampling of the first step).
    let pushed = track("pushed");
    let d = ((pushed[60].0 - pushed[0].0).powi(2) + (pushed[60].1 - pushed[0].1).powi(2)).sqrt();
    assert!((d - 1.94).abs() < 0.1, "pushed moved {d} m");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("ms/step"), "summary line missing: {stderr}");
}

#[test]
fn every_k_and_json_lines() {
    let dir = tmp_dir("jsonl");
    let path = dir.join("t.jsonl");
    let out = tribo(&["run", "bounce", "--steps", "20", "--every", "5", "--out", s(&path)]);
    assert!(out.status.success());
    let text = std::fs::read_to_string(&path).expect("jsonl");
    let records: Vec<serde_json::Value> = text.lines().map(|l| serde_json::from_str(l).expect("json")).collect();
    // 6 bodies × steps {0, 5, 10, 15, 20}.
    assert_eq!(records.len(), 6 * 5);
    let steps: std::collections::BTreeSet<u64> = records.iter().filter_map(|r| r["step"].as_u64()).collect();
    assert_eq!(steps.into_iter().collect::<Vec<_>>(), vec![0, 5, 10, 15, 20]);
    // A falling ball: y(t) = y0 − g t²/2 at t = 1/3 s, within 1 mm.
    let ball = records
        .iter()
        .find(|r| r["body"] == "ball_e_0" && r["step"] == 20)
        .expect("ball record");
    let t = 20.0 / 60.0;
    let y = ball["y"].as_f64().expect("y");
    assert!((y - (3.25 - 0.5 * 9.81 * t * t)).abs() < 1e-3, "y = {y}");
}

#[test]
fn contacts_csv_reports_stick_and_slip() {
    let dir = tmp_dir("contacts");
    let path = dir.join("c.csv");
    let out = tribo(&["run", "incline", "--steps", "30", "--contacts", s(&path)]);
    assert!(out.status.success());
    let text = std::fs::read_to_string(&path).expect("contacts");
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("step,time,body_a,body_b,x,y,normal_x,normal_y,normal_impulse,friction_impulse,state,slip_speed")
    );
    let rows: Vec<Vec<String>> = lines.map(|l| l.split(',').map(str::to_string).collect()).collect();
    let last: Vec<&Vec<String>> = rows.iter().filter(|r| r[0] == "30").collect();
    assert!(last
        .iter()
        .any(|r| r.contains(&"at_rest".to_string()) && r[10] == "stick"));
    assert!(last
        .iter()
        .any(|r| r.contains(&"pushed".to_string()) && r[10] == "slip"));
    // Coulomb: |friction| ≤ μs · normal at every point (μs = 0.6, tolerance 1e-4 N·s).
    for r in &rows {
        let (n, f): (f64, f64) = (r[8].parse().expect("n"), r[9].parse().expect("f"));
        assert!(f.abs() <= 0.6 * n + 1e-4, "{r:?}");
    }
}

#[test]
fn pictures_decode_and_are_not_blank() {
    let dir = tmp_dir("pictures");
    for ext in ["png", "svg", "gif"] {
        let path = dir.join(format!("p.{ext}"));
        let out = tribo(&["run", "incline", "--steps", "40", "--render", s(&path)]);
        assert!(out.status.success(), "{ext}: {}", String::from_utf8_lossy(&out.stderr));
        let bytes = std::fs::read(&path).expect("picture");
        match ext {
            "png" => {
                let pixmap = tiny_skia::Pixmap::decode_png(&bytes).expect("png decodes");
                let mut colors = std::collections::BTreeSet::new();
                for p in pixmap.pixels() {
                    colors.insert((p.red(), p.green(), p.blue()));
                }
                assert!(colors.len() > 20, "only {} colours", colors.len());
            }
            "svg" => {
                let text = String::from_utf8(bytes).expect("svg text");
                assert!(text.contains("<svg") && text.trim_end().ends_with("</svg>"));
                assert!(
                    text.matches("<path").count() + text.matches("<polygon").count() + text.matches("<circle").count()
                        >= 4
                );
            }
            _ => {
                let mut options = gif::DecodeOptions::new();
                options.set_color_output(gif::ColorOutput::RGBA);
                let mut decoder = options.read_info(std::io::Cursor::new(bytes)).expect("gif decodes");
                let mut frames = 0;
                while let Ok(Some(_)) = decoder.read_next_frame() {
                    frames += 1;
                }
                assert!(frames >= 10, "{frames} frames");
            }
        }
    }
}

#[test]
fn export_then_run_gives_identical_trajectories() {
    let dir = tmp_dir("roundtrip");
    let scene = dir.join("incline.json");
    assert!(tribo(&["export", "incline", s(&scene)]).status.success());
    let (a, b) = (dir.join("a.csv"), dir.join("b.csv"));
    assert!(tribo(&["run", "incline", "--steps", "50", "--out", s(&a)])
        .status
        .success());
    assert!(tribo(&["run", s(&scene), "--steps", "50", "--out", s(&b)])
        .status
        .success());
    let (ta, tb) = (std::fs::read(&a).expect("a"), std::fs::read(&b).expect("b"));
    assert!(!ta.is_empty());
    assert_eq!(ta, tb, "exported scene ran differently");
}

/// Malformed scene files: non-zero exit, one message naming the place, no panic, no output.
#[test]
fn malformed_scenes_are_rejected_with_their_place() {
    let body = |shape: &str| {
        format!(
            r#"{{"bodies": [{{"name": "g", "type": "static", "shapes": [{{"type": "box", "half_extents": [5, 1]}}]}},
{{"name": "b", "type": "dynamic", "position": [0, 2], "shapes": [{shape}]}}]}}"#
        )
    };
    let joint = |joint: &str| {
        format!(
            r#"{{"bodies": [{{"name": "g", "type": "static"}},
{{"name": "b", "type": "dynamic", "position": [0, 2], "shapes": [{{"type": "circle", "radius": 0.5}}]}}],
"joints": [{joint}]}}"#
        )
    };
    let cases: Vec<(&str, String, &str)> = vec![
        (
            "unknown field",
            r#"{"gravity": [0, -9.81], "colour": "red"}"#.into(),
            "colour",
        ),
        (
            "wrong type",
            body(r#"{"type": "circle", "radius": "big"}"#),
            "bodies[1].shapes[0].radius",
        ),
        (
            "negative radius",
            body(r#"{"type": "circle", "radius": -1}"#),
            "bodies[1].shapes[0].radius",
        ),
        (
            "restitution out of range",
            body(r#"{"type": "circle", "radius": 1, "material": {"restitution": 1.5}}"#),
            "bodies[1].shapes[0].material.restitution",
        ),
        (
            "static below dynamic friction",
            body(r#"{"type": "circle", "radius": 1, "material": {"friction_static": 0.2, "friction_dynamic": 0.5}}"#),
            "bodies[1].shapes[0].material.friction_static",
        ),
        (
            "unknown material",
            body(r#"{"type": "circle", "radius": 1, "material": "steel"}"#),
            "bodies[1].shapes[0].material",
        ),
        (
            "degenerate polygon",
            body(r#"{"type": "polygon", "vertices": [[0, 0], [1, 0], [2, 0]]}"#),
            "bodies[1].shapes[0].vertices",
        ),
        (
            "unknown shape type",
            body(r#"{"type": "triangle", "radius": 1}"#),
            "bodies[1].shapes[0].type",
        ),
        (
            "chain with a repeated point",
            body(r#"{"type": "chain", "points": [[0, 0], [1, 0], [1, 0], [2, 1]]}"#),
            "bodies[1].shapes[0].points[2]",
        ),
        (
            "chain loop closing on its first point",
            body(r#"{"type": "chain", "loop": true, "points": [[0, 0], [1, 0], [1, 1], [0, 0]]}"#),
            "bodies[1].shapes[0].points[0]",
        ),
        (
            "chain loop of two points",
            body(r#"{"type": "chain", "loop": true, "points": [[0, 0], [1, 0]]}"#),
            "bodies[1].shapes[0].points",
        ),
        (
            "chain without points",
            body(r#"{"type": "chain", "loop": true}"#),
            "bodies[1].shapes[0].points",
        ),
        (
            "chain loop flag not a boolean",
            body(r#"{"type": "chain", "loop": 1, "points": [[0, 0], [1, 0]]}"#),
            "bodies[1].shapes[0].loop",
        ),
        (
            "truncated JSON",
            r#"{"bodies": [{"name": "b", "type": "dyn"#.into(),
            "line 1",
        ),
        ("number out of range", r#"{"dt": 1e999}"#.into(), "line 1"),
        ("dt not positive", r#"{"dt": -0.01}"#.into(), "dt"),
        ("zero substeps", r#"{"substeps": 0}"#.into(), "substeps"),
        (
            "unknown body type",
            r#"{"bodies": [{"type": "floating"}]}"#.into(),
            "bodies[0].type",
        ),
        (
            "field of another shape",
            body(r#"{"type": "circle", "radius": 1, "half_extents": [1, 1]}"#),
            "half_extents",
        ),
        (
            "joint to a body that does not exist",
            joint(r#"{"body_a": 0, "body_b": 7, "anchor": [0, 0]}"#),
            "joints[0].body_b",
        ),
        (
            "joint to an unknown name",
            joint(r#"{"body_a": "ground", "body_b": "b", "anchor": [0, 0]}"#),
            "joints[0].body_a",
        ),
        (
            "joint of a body with itself",
            joint(r#"{"body_a": 1, "body_b": "b", "anchor": [0, 0]}"#),
            "joints[0].body_b",
        ),
        (
            "joint limits upside down",
            joint(r#"{"body_a": 0, "body_b": 1, "anchor": [0, 0], "limit": [1, -1]}"#),
            "joints[0].limit",
        ),
        (
            "joint motor with negative torque",
            joint(r#"{"body_a": 0, "body_b": 1, "anchor": [0, 0], "motor": {"speed": 1, "max_torque": -5}}"#),
            "joints[0].motor.max_torque",
        ),
        (
            "joint without anchor",
            joint(r#"{"body_a": 0, "body_b": 1}"#),
            "joints[0]",
        ),
    ];
    let dir = tmp_dir("malformed");
    for (what, text, place) in cases {
        let scene = dir.join("bad.json");
        std::fs::write(&scene, &text).expect("write scene");
        let outputs = [dir.join("t.csv"), dir.join("c.csv"), dir.join("p.png")];
        let out = tribo(&[
            "run",
            s(&scene),
            "--out",
            s(&outputs[0]),
            "--contacts",
            s(&outputs[1]),
            "--render",
            s(&outputs[2]),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            out.status.code(),
            Some(1),
            "{what}: exit {:?}, stderr {stderr}",
            out.status
        );
        assert!(!stderr.contains("panicked"), "{what}: {stderr}");
        assert!(stderr.contains(place), "{what}: message should name {place}: {stderr}");
        assert!(
            stderr.contains("line "),
            "{what}: message should give line:column: {stderr}"
        );
        assert_eq!(stderr.trim().lines().count(), 1, "{what}: one message: {stderr}");
        for o in &outputs {
            assert!(!o.exists(), "{what}: {} was written", o.display());
            assert!(!o
                .with_extension(format!("{}.tmp", o.extension().and_then(|e| e.to_str()).unwrap_or("")))
                .exists());
        }
    }
}

/// `--threads` changes who does the work, never the result: the trajectories of a scene
/// with stacking, sliding and new contacts are byte-identical with 1 and 2 threads.
#[test]
fn threads_give_byte_identical_trajectories() {
    let dir = tmp_dir("threads");
    let mut outputs = Vec::new();
    for threads in ["1", "2"] {
        let out_csv = dir.join(format!("t{threads}.csv"));
        let out = tribo(&[
            "run",
            "card_house",
            "--steps",
            "120",
            "--threads",
            threads,
            "--out",
            s(&out_csv),
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        outputs.push(std::fs::read(&out_csv).expect("trajectory written"));
    }
    assert!(outputs[0].len() > 1000);
    assert!(outputs[0] == outputs[1], "1 and 2 threads differ");
}

#[test]
fn bad_flags_are_rejected_before_any_output() {
    let dir = tmp_dir("flags");
    let out_csv = dir.join("t.csv");
    for args in [
        vec!["run", "incline", "--dt=-1", "--out"],
        vec!["run", "incline", "--substeps", "0", "--out"],
        vec!["run", "incline", "--threads", "0", "--out"],
        vec!["run", "no_such_scene", "--out"],
    ] {
        let mut args: Vec<&str> = args;
        args.push(s(&out_csv));
        let out = tribo(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert!(!out_csv.exists());
    }
    let out = tribo(&["run", "incline", "--render", s(&dir.join("p.bmp"))]);
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn validate_prints_the_table_and_writes_a_self_contained_report() {
    let dir = tmp_dir("validate");
    let report = dir.join("report");
    let out = tribo(&["validate", "--report", s(&report)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("incline_stick") && stdout.contains("slip_to_roll"));
    let summary = stdout
        .lines()
        .rev()
        .find(|l| l.contains("passed"))
        .expect("summary line");
    assert!(summary.ends_with(", 0 failed"), "{summary}");
    let html = std::fs::read_to_string(report.join("index.html")).expect("report");
    assert!(html.contains("<svg") && html.contains("data:image/png;base64,"));
    assert!(
        !html.contains("http://") && !html.contains("https://"),
        "report must not need the network"
    );
}

/// Built-in scenes run their step hooks in the CLI as in the benchmark: junkyard's
/// kinematic pusher is driven to 60 sin(0.2 n / 60) m (its velocity set before step n so
/// it arrives at the end of it, as Box2D's `b2Body_SetTargetTransform`): after 60 steps it
/// is at 60 sin(0.2 · 59/60) = 11.69 m (1 mm: one step's f32 integration), where the scene
/// file alone leaves it at 0; and rain's hook creates a column of 275 ragdoll bodies every
/// 8 steps (3 columns by step 17, so 1 + 825 bodies) and draws them.
#[test]
fn built_in_scenes_run_their_step_hooks() {
    let dir = tmp_dir("hooks");
    let csv = dir.join("junk.csv");
    let out = tribo(&["run", "junkyard", "--steps", "60", "--every", "60", "--out", s(&csv)]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let rows = read_csv(&csv);
    let pusher = rows.iter().find(|r| r.0 == 60 && r.1 == "pusher").expect("pusher row");
    let expected = 60.0 * (0.2f64 * 59.0 / 60.0).sin();
    assert!(
        (pusher.2 - expected).abs() < 1e-3,
        "pusher at {} m, expected {expected}",
        pusher.2
    );
    let png = dir.join("rain.png");
    let out = tribo(&["run", "rain", "--steps", "17", "--render", s(&png)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("826 bodies"), "{stderr}");
    assert!(png.exists());
}

//! The `dqhand` command run as a user runs it: help, info, skin, bench, demo and bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::{json, Value};

/// A fresh, empty directory for one test.
fn temp_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("dqhand-cli-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create temp dir");
    dir
}

/// Runs `dqhand` with `args`.
fn dqhand<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dqhand")).args(args).output().expect("run dqhand")
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Asserts that the command exited with `code`, showing its output if not.
#[track_caller]
fn assert_exit(out: &Output, code: i32) {
    assert_eq!(out.status.code(), Some(code), "exit status {:?}\nstdout:\n{}\nstderr:\n{}", out.status, stdout(out), stderr(out));
}

/// Runs `dqhand` expecting success; returns stdout.
#[track_caller]
fn run_ok<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> String {
    let out = dqhand(args);
    assert_exit(&out, 0);
    stdout(&out)
}

/// Runs `dqhand` expecting a failure of the command (exit 1) reported as one line
/// `dqhand: error: …` on stderr; returns that line.
#[track_caller]
fn run_error<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> String {
    let out = dqhand(args);
    assert_exit(&out, 1);
    let err = stderr(&out);
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "expected one line on stderr, got:\n{err}");
    assert!(lines[0].starts_with("dqhand: error:"), "{err}");
    lines[0].to_owned()
}

fn write_json(path: &Path, value: &Value) {
    std::fs::write(path, serde_json::to_string_pretty(value).unwrap()).expect("write JSON");
}

fn path_arg(path: &Path) -> String {
    path.to_str().expect("UTF-8 temp path").to_owned()
}

const BUILTIN_VERTICES: usize = 8668;

// ---------------------------------------------------------------------------------------------
// Help
// ---------------------------------------------------------------------------------------------

#[test]
fn help_works_for_every_command() {
    let top = run_ok(&["--help"]);
    for sub in ["info", "hand", "skin", "bench", "demo", "metrics", "replay", "calibrate", "synthesize", "listen", "gesture-bench", "grasp", "grasp-bench", "export-skinning"] {
        assert!(top.contains(sub), "top-level help does not list {sub}:\n{top}");
        let help = run_ok(&[sub, "--help"]);
        assert!(help.contains("Usage"), "`dqhand {sub} --help`:\n{help}");
    }
    let skin = run_ok(&["skin", "--help"]);
    for option in ["--mesh", "--pose", "--method", "--out", "--no-limits"] {
        assert!(skin.contains(option), "`dqhand skin --help` lacks {option}:\n{skin}");
    }
}

// ---------------------------------------------------------------------------------------------
// info
// ---------------------------------------------------------------------------------------------

#[test]
fn info_builtin_describes_the_anatomical_hand() {
    let out = run_ok(&["info", "builtin"]);
    assert!(out.contains(&BUILTIN_VERTICES.to_string()), "no vertex count {BUILTIN_VERTICES}:\n{out}");
    assert!(out.contains("anatomical right hand"), "{out}");
    for joint in dqhand::kinematics::webxr::JOINT_NAMES {
        assert!(out.contains(joint), "joint {joint} not listed:\n{out}");
    }
}

#[test]
fn info_reads_an_exported_glb() {
    let dir = temp_dir("info-glb");
    let hand = dir.join("hand.glb");
    dqhand::io::write_skinned_glb(&dqhand::hand::build(&Default::default()).unwrap(), &hand).unwrap();
    let out = run_ok(&["info", &path_arg(&hand)]);
    assert!(out.contains("hand.glb") && out.contains(&BUILTIN_VERTICES.to_string()), "{out}");
}

// ---------------------------------------------------------------------------------------------
// hand
// ---------------------------------------------------------------------------------------------

#[test]
fn hand_writes_a_rigged_hand_of_the_users_size_with_collision_proxies() {
    let dir = temp_dir("hand");
    let out = dir.join("left.glb");
    let printed = run_ok(&["hand", "--length", "0.17", "--breadth", "0.075", "--side", "left", "--vertices", "2000", "--out", &path_arg(&out)]);
    assert!(printed.contains("left hand") && printed.contains("2000 vertices"), "{printed}");
    let model = dqhand::io::load_gltf(&out).unwrap();
    assert_eq!(model.mesh.vertex_count(), 2000);
    dqhand::geometry::check_closed(model.mesh.indices()).unwrap();
    // A left hand has its thumb on +X; the hand is 0.17 m from the wrist crease to the tip.
    let thumb_tip = model.skeleton.rest_world()[model.skeleton.find("thumb-tip").unwrap()].translation;
    assert!(thumb_tip.x > 0.0, "{thumb_tip}");
    let reach = (0..model.mesh.vertex_count()).map(|v| -model.mesh.position(v).z).fold(0.0, f32::max);
    assert!((reach / 0.17 - 1.0).abs() < 0.04, "{reach}");
    // Every bone with skin carries a proxy: capsules on the phalanges, hulls on the palm.
    let doc: Value = serde_json::from_slice(&glb_json(&std::fs::read(&out).unwrap())).unwrap();
    let proxy = |name: &str| {
        let node = doc["nodes"].as_array().unwrap().iter().find(|n| n["name"] == name).unwrap();
        node["extras"]["dqhand_collision"].clone()
    };
    let capsule = proxy("index-finger-phalanx-intermediate");
    let radius = capsule["capsule"]["radius"].as_f64().unwrap();
    assert!((0.005..0.015).contains(&radius), "{capsule}");
    assert!(proxy("wrist")["convex_hull"]["points"].as_array().unwrap().len() >= 4);
    assert!(proxy("index-finger-tip").is_null(), "tips have no skin of their own");
}

#[test]
fn hand_refuses_implausible_measurements() {
    let dir = temp_dir("hand-bad");
    let out = path_arg(&dir.join("bad.glb"));
    for (args, words) in [
        (vec!["--length", "0"], "length"),
        (vec!["--length=-0.2"], "length"),
        (vec!["--breadth", "0.3"], "breadth"),
        (vec!["--vertices", "0"], "vertices"),
    ] {
        let mut all = vec!["hand", "--out", &out];
        all.extend(args.iter().copied());
        let err = run_error(&all);
        assert!(err.contains(words), "{args:?}: {err}");
    }
    assert!(!dir.join("bad.glb").exists(), "nothing written on error");
}

/// The JSON chunk of a GLB.
fn glb_json(bytes: &[u8]) -> Vec<u8> {
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    bytes[20..20 + len].to_vec()
}

// ---------------------------------------------------------------------------------------------
// skin
// ---------------------------------------------------------------------------------------------

#[test]
fn skin_writes_every_method_and_format() {
    let dir = temp_dir("skin");
    let pose = dir.join("pose.json");
    write_json(&pose, &json!({ "angles_deg": { "index-finger-phalanx-intermediate.flex": 90, "thumb-metacarpal.flex": 20 } }));
    for method in ["lb", "qb", "dqb"] {
        for ext in ["ply", "obj", "glb"] {
            let out = dir.join(format!("hand-{method}.{ext}"));
            let printed = run_ok(&["skin", "--mesh", "builtin", "--pose", &path_arg(&pose), "--method", method, "--out", &path_arg(&out)]);
            assert!(printed.contains(&BUILTIN_VERTICES.to_string()), "{printed}");
            let size = std::fs::metadata(&out).map(|m| m.len()).unwrap_or(0);
            assert!(size > 0, "{} not written", out.display());
        }
    }
}

#[test]
fn skin_accepts_no_limits() {
    let dir = temp_dir("skin-no-limits");
    let pose = dir.join("pose.json");
    write_json(&pose, &json!({ "angles_deg": { "index-finger-phalanx-intermediate.flex": 150 } }));
    let (clamped, free) = (dir.join("clamped.obj"), dir.join("free.obj"));

    let out = dqhand(&["skin", "--pose", &path_arg(&pose), "--out", &path_arg(&clamped)]);
    assert_exit(&out, 0);
    assert!(stderr(&out).contains("clamped"), "no clamping warning:\n{}", stderr(&out));

    let out = dqhand(&["skin", "--pose", &path_arg(&pose), "--no-limits", "--out", &path_arg(&free)]);
    assert_exit(&out, 0);
    assert!(!stderr(&out).contains("clamped"), "{}", stderr(&out));
    assert_ne!(std::fs::read(&clamped).unwrap(), std::fs::read(&free).unwrap(), "--no-limits made no difference");
}

#[test]
fn skin_contact_pass_moves_a_fists_skin() {
    let dir = temp_dir("skin-contact-pass");
    let pose = dir.join("fist.json");
    let mut angles = serde_json::Map::new();
    for finger in ["index-finger", "middle-finger", "ring-finger", "pinky-finger"] {
        for (bone, deg) in [("phalanx-proximal", 90), ("phalanx-intermediate", 100), ("phalanx-distal", 70)] {
            angles.insert(format!("{finger}-{bone}.flex"), json!(deg));
        }
    }
    write_json(&pose, &json!({ "angles_deg": angles }));
    let (plain, passed) = (dir.join("plain.obj"), dir.join("passed.obj"));
    let printed = run_ok(&["skin", "--pose", &path_arg(&pose), "--out", &path_arg(&plain)]);
    assert!(!printed.contains("contact pass"), "{printed}");
    let printed = run_ok(&["skin", "--pose", &path_arg(&pose), "--contact-pass", "--out", &path_arg(&passed)]);
    let moved: usize = printed.split("the contact pass moved ").nth(1).and_then(|s| s.split(' ').next()).and_then(|n| n.parse().ok()).unwrap_or_else(|| panic!("{printed}"));
    assert!(moved > 0, "{printed}");
    assert_ne!(std::fs::read(&plain).unwrap(), std::fs::read(&passed).unwrap(), "--contact-pass made no difference");
}

#[test]
fn skin_without_pose_writes_the_rest_pose() {
    let out = temp_dir("skin-rest").join("rest.ply");
    run_ok(&["skin", "--out", &path_arg(&out)]);
    assert!(out.is_file());
}

// ---------------------------------------------------------------------------------------------
// bench
// ---------------------------------------------------------------------------------------------

fn positive_number(report: &Value, pointer: &str) -> f64 {
    let x = report.pointer(pointer).and_then(Value::as_f64).unwrap_or_else(|| panic!("no number at {pointer} in {report}"));
    assert!(x.is_finite() && x > 0.0, "{pointer} = {x} is not positive and finite");
    x
}

#[test]
fn bench_json_reports_every_method() {
    let out = run_ok(&["bench", "--frames", "30", "--json"]);
    let lines: Vec<&str> = out.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "expected one JSON line:\n{out}");
    let report: Value = serde_json::from_str(lines[0]).expect("a JSON object");
    assert_eq!(report["mesh"], "builtin");
    assert_eq!(report["vertices"], BUILTIN_VERTICES);
    assert_eq!(report["bones"], 20);
    for method in ["lb", "qb", "dqb", "cor"] {
        positive_number(&report, &format!("/methods/{method}/us_per_frame"));
        positive_number(&report, &format!("/methods/{method}/fps"));
    }
    positive_number(&report, "/ratios/dqb_over_lb");
    positive_number(&report, "/ratios/dqb_over_qb");
    // Issue 33: the lookup strategy each method's deformer chose (on the AVX-512 kernel only),
    // and the roofline.
    let avx512 = dqhand::skin::Kernel::best() == dqhand::skin::Kernel::Avx512;
    positive_number(&report, "/cor_centres_ms");
    positive_number(&report, "/contact_pass/us_per_frame");
    for method in ["lb", "qb", "dqb", "cor"] {
        let chosen = &report["chosen_strategy"][method];
        match chosen.as_str() {
            Some(name) => assert!(avx512 && dqhand::skin::Strategy::named(name).is_some(), "{method}: {chosen} is not a strategy, or there is no AVX-512 kernel"),
            None => assert!(!avx512 && chosen.is_null(), "{method}: {chosen} where the AVX-512 kernel runs"),
        }
    }
    for key in ["l2_read_bytes_per_s", "l2_write_bytes_per_s", "peak_flops"] {
        positive_number(&report, &format!("/machine/{key}"));
    }
    // The thread variants timed back to back besides interleaved: one thread and each count
    // timed, with and without normals.
    let streamed = report["threads_back_to_back"].as_array().expect("back-to-back thread rows");
    let counts: Vec<u64> = report["variants"].as_array().expect("variants").iter().filter_map(|v| v["threads"].as_u64()).collect();
    assert_eq!(streamed.len(), 2 * (1 + counts.iter().filter(|&&t| t > 1).count() / 2), "{streamed:?}");
    for normals in [true, false] {
        assert!(streamed.iter().any(|r| r["threads"] == 1 && r["normals"] == normals), "no one-thread row (normals {normals}) in {streamed:?}");
    }
    for i in 0..streamed.len() {
        positive_number(&report, &format!("/threads_back_to_back/{i}/us_per_frame"));
    }
    assert!(report["crew_wake"].is_array());
    let rows = report["roofline"].as_array().expect("roofline rows");
    assert_eq!(rows.len(), 8, "a row per method, with and without normals");
    for i in 0..rows.len() {
        for key in ["bytes_read", "bytes_written", "flops", "bound_us", "over_bound"] {
            positive_number(&report, &format!("/roofline/{i}/{key}"));
        }
    }
}

// ---------------------------------------------------------------------------------------------
// demo
// ---------------------------------------------------------------------------------------------

#[test]
fn demo_writes_the_hand_and_every_gesture() {
    let dir = temp_dir("demo");
    run_ok(&["demo", "--out", &path_arg(&dir)]);
    assert!(dir.join("hand.glb").is_file(), "hand.glb missing");
    let gestures = dqhand::gesture::GESTURES;
    assert!(!gestures.is_empty());
    for (i, g) in gestures.iter().enumerate() {
        let stem = format!("{i:02}-{}", g.name);
        for suffix in ["pose.json", "lb.glb", "qb.glb", "dqb.glb"] {
            let file = dir.join(format!("{stem}.{suffix}"));
            assert!(file.is_file(), "{} missing", file.display());
        }
    }
    // The rigged hand it writes loads back.
    let model = dqhand::io::load_gltf(&dir.join("hand.glb")).expect("demo's hand.glb loads");
    assert_eq!(model.mesh.vertex_count(), BUILTIN_VERTICES);
}

// ---------------------------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------------------------

#[test]
fn info_missing_file_is_a_one_line_error() {
    let line = run_error(&["info", "/nonexistent.glb"]);
    assert!(line.contains("/nonexistent.glb"), "{line}");
}

#[test]
fn io_error_reason_is_printed_once() {
    let line = run_error(&["info", "/nonexistent.glb"]);
    assert_eq!(line.matches("(os error").count(), 1, "{line}");
}

#[test]
fn info_truncated_glb_is_a_one_line_error() {
    let dir = temp_dir("info-truncated");
    let hand = dir.join("truncated-hand.glb");
    dqhand::io::write_skinned_glb(&dqhand::hand::build(&Default::default()).unwrap(), &hand).unwrap();
    let bytes = std::fs::read(&hand).unwrap();
    std::fs::write(&hand, &bytes[..bytes.len() / 2]).unwrap();
    let line = run_error(&["info", &path_arg(&hand)]);
    assert!(line.contains("truncated-hand.glb"), "{line}");
}

#[test]
fn skin_unknown_dof_lists_valid_names() {
    let dir = temp_dir("skin-unknown-dof");
    let pose = dir.join("typo.pose.json");
    write_json(&pose, &json!({ "angles_deg": { "index-finger-knuckle.flex": 30 } }));
    let line = run_error(&["skin", "--pose", &path_arg(&pose), "--out", &path_arg(&dir.join("x.ply"))]);
    for part in ["typo.pose.json", "index-finger-knuckle.flex", "valid", "index-finger-phalanx-proximal.flex"] {
        assert!(line.contains(part), "{part:?} not in {line}");
    }
    assert!(!dir.join("x.ply").exists());
}

#[test]
fn skin_invalid_pose_json_names_the_file() {
    let dir = temp_dir("skin-bad-json");
    let pose = dir.join("broken.pose.json");
    std::fs::write(&pose, "{ \"angles_deg\": ").unwrap();
    let line = run_error(&["skin", "--pose", &path_arg(&pose), "--out", &path_arg(&dir.join("x.ply"))]);
    assert!(line.contains("broken.pose.json"), "{line}");
}

#[test]
fn skin_unknown_output_format_is_an_error() {
    let out = temp_dir("skin-bad-ext").join("hand.stl");
    let line = run_error(&["skin", "--out", &path_arg(&out)]);
    assert!(line.contains("hand.stl"), "{line}");
}

#[test]
fn unknown_method_is_a_usage_error() {
    let out = temp_dir("skin-bad-method").join("x.ply");
    let result = dqhand(&["skin", "--method", "foo", "--out", &path_arg(&out)]);
    assert_exit(&result, 2);
    assert!(stderr(&result).contains("foo"), "{}", stderr(&result));
    assert!(!out.exists());
}

#[test]
fn unknown_subcommand_is_a_usage_error() {
    assert_exit(&dqhand(&["frobnicate"]), 2);
    assert_exit(&dqhand::<&str>(&[]), 2);
}

#[test]
fn metrics_json_and_csv_cover_every_sweep_and_method() {
    let dir = temp_dir("metrics-csv");
    let out = run_ok(&["metrics", "--json", "--csv", &path_arg(&dir)]);
    let report: Value = serde_json::from_str(out.trim()).expect("one JSON object");
    assert_eq!(report["closed"], json!(true));
    let sweeps = report["sweeps"].as_object().unwrap();
    for name in ["index-pip", "index-mcp", "fist", "index-pip-twist", "wrist-twist"] {
        let s = &sweeps[name];
        let n = s["values"].as_array().unwrap().len();
        for m in ["lb", "qb", "dqb", "cor"] {
            assert_eq!(s[m]["volume"].as_array().unwrap().len(), n, "{name} {m}");
        }
        let csv = std::fs::read_to_string(dir.join(format!("{name}.csv"))).unwrap();
        assert_eq!(csv.lines().count(), 1 + 4 * n, "{name}.csv");
    }
}

#[test]
fn metrics_on_an_open_mesh_say_volume_is_undefined_and_report_the_rest() {
    let Ok(hand) = std::env::var("DQHAND_WEBXR_HAND").or_else(|_| {
        let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../third_party/node_modules/@webxr-input-profiles/assets/dist/profiles/generic-hand/right.glb");
        if p.exists() { Ok(path_arg(&p)) } else { Err(()) }
    }) else {
        panic!("the WebXR generic hand is missing: run `make test` (it runs `npm ci` in third_party/)");
    };
    let result = dqhand(&["metrics", "--mesh", &hand, "--json"]);
    assert_exit(&result, 0);
    assert!(stderr(&result).contains("volume is undefined"), "{}", stderr(&result));
    let report: Value = serde_json::from_str(stdout(&result).trim()).unwrap();
    assert_eq!(report["closed"], json!(false));
    assert!(report["sweeps"]["index-pip"]["dqb"]["volume"][0].is_null());
    assert!(report["sweeps"]["index-pip"]["dqb"]["min_distance"][0].as_f64().unwrap() > 0.99);
}

#[test]
fn readme_metrics_table_is_the_commands_output() {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../README.md")).unwrap();
    let begin = readme.find("<!-- metrics:begin -->\n").expect("README metrics marker") + "<!-- metrics:begin -->\n".len();
    let end = readme.find("<!-- metrics:end -->").expect("README metrics end marker");
    assert_eq!(&readme[begin..end], run_ok(&["metrics", "--markdown"]), "regenerate the README table with `dqhand metrics --markdown`");
}

/// `skin --poses`: a batch of pose lines (a replay's output among them) is deformed across
/// the cores and written one file each, each the file `skin --pose` writes for that pose; a
/// bad line is an error naming the file and line.
#[test]
fn skin_poses_writes_one_file_per_pose_as_skin_pose_does() {
    let dir = temp_dir("skin-poses");
    let fist = json!({"angles_deg": {"index-finger-phalanx-proximal.flex": 80, "index-finger-phalanx-intermediate.flex": 95}});
    let spread = json!({"t": 1.5, "tracking": "tracking", "model": "full", "angles_deg": {"thumb-metacarpal.abd": 30}});
    let lines = [fist.to_string(), String::new(), spread.to_string(), "{}".to_owned()];
    let poses = dir.join("poses.jsonl");
    std::fs::write(&poses, lines.join("\n")).unwrap();
    let out = dir.join("batch");
    let printed = run_ok(&["skin", "--poses", &path_arg(&poses), "--out", &path_arg(&out), "--format", "ply"]);
    assert!(printed.contains("deformed 3 poses") && printed.contains("frames/s"), "{printed}");
    for (i, pose) in [&fist, &spread, &json!({})].into_iter().enumerate() {
        let mut single = pose.clone();
        single.as_object_mut().unwrap().retain(|k, _| k != "t" && k != "tracking");
        let file = dir.join(format!("single-{i}.json"));
        write_json(&file, &single);
        let alone = dir.join(format!("single-{i}.ply"));
        run_ok(&["skin", "--pose", &path_arg(&file), "--out", &path_arg(&alone)]);
        assert_eq!(std::fs::read(out.join(format!("pose-{i:05}.ply"))).unwrap(), std::fs::read(&alone).unwrap(), "pose {i}");
    }
    assert!(!out.join("pose-00003.ply").exists());
    std::fs::write(&poses, format!("{fist}\n{{\"angles_deg\": 3}}\n")).unwrap();
    let e = run_error(&["skin", "--poses", &path_arg(&poses), "--out", &path_arg(&out)]);
    assert!(e.contains("poses.jsonl: line 2: not a pose"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// A copied or installed binary
// ---------------------------------------------------------------------------------------------

/// The dqhand binary copied into `dir` as it would be on a machine without this checkout:
/// every occurrence of the checkout's path in it is replaced by a path of the same length
/// that does not exist, so anything it looks up at a path compiled in (the source tree it was
/// built from) is not there, as on a user's machine.
#[cfg(unix)]
fn relocated_binary(dir: &Path) -> PathBuf {
    use std::os::unix::ffi::OsStrExt;
    use std::os::unix::fs::PermissionsExt;
    let checkout = Path::new(env!("CARGO_MANIFEST_DIR")).ancestors().nth(2).expect("the workspace root");
    let from = checkout.as_os_str().as_bytes();
    let to: Vec<u8> = std::iter::once(b'/').chain(std::iter::repeat(b'x')).take(from.len()).collect();
    assert!(from.len() >= 4 && !Path::new(std::ffi::OsStr::from_bytes(&to)).exists(), "{} cannot be hidden", checkout.display());
    let mut bytes = std::fs::read(env!("CARGO_BIN_EXE_dqhand")).expect("read the built binary");
    let mut i = 0;
    while let Some(k) = bytes[i..].windows(from.len()).position(|w| w == from) {
        bytes[i + k..i + k + from.len()].copy_from_slice(&to);
        i += k + from.len();
    }
    let exe = dir.join("dqhand");
    std::fs::write(&exe, &bytes).expect("write the copy");
    std::fs::set_permissions(&exe, std::fs::Permissions::from_mode(0o755)).unwrap();
    exe
}

/// Runs `exe` with `args` in `cwd` (retrying while the copy just written is still busy: a
/// test thread that forked meanwhile may hold it open for writing for a moment).
fn spawn_in(exe: &Path, cwd: &Path, args: &[&str], piped: bool) -> std::process::Child {
    let stdio = || if piped { std::process::Stdio::piped() } else { std::process::Stdio::inherit() };
    for _ in 0..50 {
        match Command::new(exe).args(args).current_dir(cwd).stdout(stdio()).stderr(stdio()).spawn() {
            Err(e) if e.raw_os_error() == Some(26) => std::thread::sleep(std::time::Duration::from_millis(100)),
            spawned => return spawned.expect("run the copied dqhand"),
        }
    }
    panic!("{} stayed busy", exe.display());
}

fn output_in(exe: &Path, cwd: &Path, args: &[&str]) -> Output {
    spawn_in(exe, cwd, args, true).wait_with_output().unwrap()
}

/// A copy of the binary, run away from the source tree it was built from (which it cannot
/// reach: see `relocated_binary`), finds everything the documented commands need: the
/// built-in scenes and their meshes, the grasp recording `demo --scene` plays (made on first
/// use), and the built page beside the binary; without a page it names where it looked.
#[cfg(unix)]
#[test]
fn a_copied_binary_runs_the_scene_commands_without_the_source_tree() {
    use std::io::BufRead;
    let dir = temp_dir("relocated");
    let (bin, cwd) = (dir.join("bin"), dir.join("cwd"));
    std::fs::create_dir_all(&bin).unwrap();
    std::fs::create_dir_all(&cwd).unwrap();
    let exe = relocated_binary(&bin);

    // A built-in scene and its mesh (the teapot): a scripted recording made, then run through
    // the manipulation loop, which picks up both objects.
    let out = output_in(&exe, &cwd, &["synthesize", "--scene", "grasp", "--side", "right", "--out", "grasp.jsonl"]);
    assert_exit(&out, 0);
    let out = output_in(&exe, &cwd, &["grasp", "--scene", "grasp", "--input", "grasp.jsonl", "--trace", "trace.jsonl"]);
    assert_exit(&out, 0);
    let trace = std::fs::read_to_string(cwd.join("trace.jsonl")).unwrap();
    for object in ["ball", "teapot"] {
        assert!(trace.contains(&format!("\"held\":\"{object}\"")), "the {object} was never held");
    }

    // No page anywhere: the error says where it looked (here, beside the binary).
    let out = output_in(&exe, &cwd, &["demo", "--no-open", "--port", "0"]);
    assert_exit(&out, 1);
    let e = stderr(&out);
    assert!(e.contains("viewer/dist") && e.contains(&bin.join("viewer").display().to_string()) && e.contains("--viewer"), "{e}");

    // The page beside the binary, and `demo --scene grasp` with no input: it makes the grasp
    // recording itself and plays it; a viewer sees the hand tracked.
    std::fs::create_dir_all(bin.join("viewer")).unwrap();
    std::fs::write(bin.join("viewer/index.html"), "<!doctype html><title>viewer</title>").unwrap();
    let mut child = spawn_in(&exe, &cwd, &["demo", "--no-open", "--port", "0", "--scene", "grasp"], true);
    let stderr_pipe = child.stderr.take().unwrap();
    let errors = std::thread::spawn(move || std::io::read_to_string(stderr_pipe).unwrap_or_default());
    let mut lines = std::io::BufReader::new(child.stdout.take().unwrap()).lines();
    let mut banner = String::new();
    let address = loop {
        let Some(Ok(line)) = lines.next() else {
            let _ = child.kill();
            let _ = child.wait();
            panic!("demo --scene grasp stopped:\n{banner}\n{}", errors.join().unwrap());
        };
        banner += &line;
        banner.push('\n');
        if let Some(url) = line.strip_prefix("viewer: http://") {
            break url.trim_end_matches('/').to_owned();
        }
    };
    std::thread::spawn(move || lines.for_each(drop));
    let tracked = (|| {
        let (mut ws, _) = tungstenite::connect(format!("ws://{address}/stream")).ok()?;
        if let tungstenite::stream::MaybeTlsStream::Plain(s) = ws.get_mut() {
            s.set_read_timeout(Some(std::time::Duration::from_secs(20))).unwrap();
        }
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
        while std::time::Instant::now() < deadline {
            match ws.read().ok()? {
                tungstenite::Message::Text(t) => {
                    let m: Value = serde_json::from_str(&t).ok()?;
                    if m["type"] == "input" && m["tracking"] == "tracking" {
                        return Some(m);
                    }
                }
                tungstenite::Message::Binary(b) if b.starts_with(b"DQHF") && b.len() >= 12 => {
                    // Acknowledged, or the server stops at three frames (the sequence: bytes 8–11).
                    let seq = u32::from_le_bytes([b[8], b[9], b[10], b[11]]);
                    ws.send(tungstenite::Message::text(format!(r#"{{"type":"ack","seq":{seq}}}"#))).ok()?;
                }
                _ => {}
            }
        }
        None
    })();
    let _ = child.kill();
    let _ = child.wait();
    assert!(banner.contains("scene: grasp, 2 objects (ball, teapot)") && banner.contains("played in real time"), "{banner}");
    assert!(tracked.is_some(), "no viewer saw the hand tracked:\n{banner}\n{}", errors.join().unwrap());
}

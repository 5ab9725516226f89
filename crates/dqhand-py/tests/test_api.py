"""dqhand's Python API beyond skinning (issue 31), on the installed wheel: retargeting,
recordings, gestures, the realism metrics and glTF export.

Each is held to the Rust command line ($DQHAND_BIN) on the same input (`dqhand replay`,
`dqhand metrics`, `dqhand hand`, `dqhand skin`), to the JSON the files hold as Python's own
`json` reads it, or to a reference written here in NumPy from the definitions (forward
kinematics undone by retargeting, volume by the divergence theorem, distances to the bones).
"""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import dqhand
from wrists import random_wrists

ROOT = Path(__file__).resolve().parents[3]
RECORDINGS = ROOT / "crates/dqhand/data/recordings"
GESTURES_FILE = ROOT / "crates/dqhand/data/gestures.json"


@pytest.fixture(scope="module")
def hand():
    return dqhand.Hand.builtin()


@pytest.fixture(scope="module")
def binary():
    path = os.environ.get("DQHAND_BIN")
    if not path:
        pytest.fail("DQHAND_BIN must name the dqhand binary (make test sets it)")
    return path


def cli(binary, *args):
    return subprocess.run([binary, *map(str, args)], check=True, capture_output=True, text=True).stdout


def random_angles(hand, count, seed):
    """Angles within each joint's range, radians, the palm flat (its metacarpals unflexed: the
    palm frame the retargeter reads stays the rest one)."""
    rng = np.random.default_rng(seed)
    low, high = hand.limits[:, 0].astype(np.float64), hand.limits[:, 1].astype(np.float64)
    angles = low + (high - low) * rng.uniform(0.1, 0.9, size=(count, len(low)))
    for name in ("ring-finger-metacarpal.flex", "pinky-finger-metacarpal.flex"):
        angles[:, hand.dof_names.index(name)] = 0
    return angles


def apart(hand, joints):
    """Poses whose thumb tip is more than 2.5 cm from every fingertip: the retargeter's contact
    correction (within 2 cm) leaves them alone, so they must come back exactly."""
    tips = [dqhand.WEBXR_JOINTS.index(f"{f}-finger-tip") for f in ("index", "middle", "ring", "pinky")]
    thumb = joints[:, dqhand.WEBXR_JOINTS.index("thumb-tip")]
    return np.linalg.norm(joints[:, tips] - thumb[:, None], axis=2).min(axis=1) > 0.025


def one_line(error):
    message = str(error.value)
    assert "\n" not in message, message
    return message


# ---- Retargeting ----


@pytest.fixture(scope="module")
def tracked(hand):
    """Poses of this hand (free of thumb contacts) and their WebXR joints and keypoints."""
    angles, wrists = random_angles(hand, 40, seed=1), random_wrists(40, seed=2)
    keep = apart(hand, hand.joints(angles, wrists))
    angles, wrists = angles[keep], wrists[keep]
    assert len(angles) >= 8
    return angles, wrists, hand.joints(angles, wrists), hand.keypoints(angles, wrists)


def test_fitting_webxr_joints_undoes_forward_kinematics(hand, tracked):
    angles, wrists, joints, _ = tracked
    fitted, fitted_wrists = hand.fit(joints, "webxr")
    assert fitted.shape == angles.shape and fitted.dtype == np.float32 and fitted_wrists.shape == (len(angles), 4, 4)
    np.testing.assert_allclose(fitted, angles, atol=2e-3)
    np.testing.assert_allclose(fitted_wrists, wrists, atol=1e-4)
    np.testing.assert_allclose(hand.joints(fitted, fitted_wrists), joints, atol=2e-4)


def test_fitting_mediapipe_landmarks_gives_the_same_pose(hand, tracked):
    angles, wrists, joints, keypoints = tracked
    from_joints, _ = hand.fit(joints, "webxr")
    from_landmarks, landmark_wrists = hand.fit(keypoints)  # "mediapipe" is the default
    np.testing.assert_allclose(from_landmarks, from_joints, atol=2e-3)
    np.testing.assert_allclose(landmark_wrists, wrists, atol=1e-4)
    np.testing.assert_allclose(hand.keypoints(from_landmarks, landmark_wrists), keypoints, atol=2e-4)


def test_fitting_reads_directions_only_and_mirrors_the_other_hand(hand, tracked):
    _, _, joints, _ = tracked
    angles, wrists = hand.fit(joints, "webxr")
    wrist = joints[:, :1]
    bigger, bigger_wrists = hand.fit(wrist + 1.25 * (joints - wrist), "webxr")
    np.testing.assert_allclose(bigger, angles, atol=1e-4)
    np.testing.assert_allclose(bigger_wrists, wrists, atol=1e-5)
    mirrored = joints * [-1, 1, 1]
    as_left, _ = hand.fit(mirrored, "webxr", side="left")
    np.testing.assert_allclose(as_left, angles, atol=1e-4)
    as_right, _ = hand.fit(mirrored, "webxr", side="right")
    assert np.abs(as_right - angles).max() > 0.1, "a left hand read as a right one is another pose"


def test_fitting_gives_the_poses_the_command_line_retargets(hand, tracked, binary, tmp_path):
    """`dqhand replay --out` with the filters off writes the retargeter's poses of a recording."""
    _, _, joints, _ = tracked
    t = np.arange(len(joints)) / 30
    dqhand.write_recording(tmp_path / "tracked.jsonl", t, joints=joints)
    (tmp_path / "raw.json").write_text(json.dumps({"filter": False}))
    cli(binary, "replay", "--input", tmp_path / "tracked.jsonl", "--config", tmp_path / "raw.json", "--out", tmp_path / "poses.jsonl")
    lines = [json.loads(line) for line in (tmp_path / "poses.jsonl").read_text().splitlines()]
    assert len(lines) == len(joints)
    expected = np.array([[np.radians(line["angles_deg"].get(name, 0.0)) for name in hand.dof_names] for line in lines])
    translations = np.array([line["wrist"]["translation"] for line in lines])
    angles, wrists = hand.fit(joints.astype(np.float32), "webxr")
    np.testing.assert_allclose(angles, expected, atol=1e-6)
    np.testing.assert_allclose(wrists[:, :3, 3], translations, atol=1e-7)


def test_bad_points_are_refused_naming_the_argument(hand):
    with pytest.raises(ValueError) as e:
        hand.fit(np.zeros((2, 20, 3)))
    assert one_line(e).startswith("points: expected an array of shape (B, 21, 3)")
    with pytest.raises(ValueError) as e:
        hand.fit(np.zeros((2, 21, 3)), "webxr")
    assert one_line(e).startswith("points: expected an array of shape (B, 25, 3)")
    with pytest.raises(ValueError) as e:
        hand.fit(np.zeros((1, 21, 3)), "openpose")
    assert one_line(e).startswith("kind: \"openpose\"")
    with pytest.raises(ValueError) as e:
        hand.fit(np.zeros((1, 21, 3)), side="middle")
    assert one_line(e).startswith("side: \"middle\"")
    points = hand.keypoints(np.zeros((3, len(hand.dof_names))))
    points[2] = 0  # no palm
    with pytest.raises(ValueError) as e:
        hand.fit(points)
    assert one_line(e).startswith("points[2]: landmarks: ")
    nan = points.copy()
    nan[1, 4, 0] = np.nan
    with pytest.raises(ValueError, match="^points: value NaN of item 1 is not finite$"):
        hand.fit(nan)
    assert [a.shape for a in hand.fit(np.zeros((0, 21, 3)))] == [(0, len(hand.dof_names)), (0, 4, 4)]


# ---- Recordings ----


def json_lines(path):
    return [json.loads(line) for line in Path(path).read_text().splitlines() if line.strip()]


def test_a_landmarks_recording_reads_as_its_json_and_writes_back(tmp_path):
    path = RECORDINGS / "gestures-landmarks.jsonl"
    lines = json_lines(path)
    recording = dqhand.read_recording(path)
    assert set(recording) == {"t", "side", "landmarks"}
    # The engine's JSON parser (serde_json's fast path, which `dqhand replay` reads with too) may
    # round a time to the float next to Python's.
    np.testing.assert_allclose(recording["t"], [line["t"] for line in lines], rtol=1e-15, atol=0)
    np.testing.assert_array_equal(recording["side"], [line.get("hand", "right") for line in lines])
    assert recording["landmarks"].shape == (len(lines), 21, 3)
    np.testing.assert_array_equal(recording["landmarks"], np.array([line["landmarks"] for line in lines], dtype=np.float32))
    dqhand.write_recording(tmp_path / "copy.jsonl", recording["t"], landmarks=recording["landmarks"], side=list(recording["side"]))
    again = dqhand.read_recording(tmp_path / "copy.jsonl")
    for key in recording:
        np.testing.assert_array_equal(again[key], recording[key])


def test_a_joints_recording_reads_as_its_json_and_writes_back(tmp_path):
    path = RECORDINGS / "gestures-joints.jsonl"
    lines = json_lines(path)[:200]
    (tmp_path / "part.jsonl").write_text("".join(json.dumps(line) + "\n" for line in lines))
    recording = dqhand.read_recording(tmp_path / "part.jsonl")
    assert {"t", "side", "joints", "joint_orientations", "joint_radii"} <= set(recording)
    names = dqhand.WEBXR_JOINTS
    np.testing.assert_array_equal(recording["joints"], np.array([[line["joints"][n]["p"] for n in names] for line in lines], dtype=np.float32))
    quaternions = np.array([[line["joints"][n].get("q", [np.nan] * 4) for n in names] for line in lines], dtype=np.float32)
    np.testing.assert_allclose(recording["joint_orientations"], quaternions, atol=1e-7)
    radii = np.array([[line["joints"][n].get("r", 0.0) for n in names] for line in lines], dtype=np.float32)
    np.testing.assert_array_equal(recording["joint_radii"], radii)
    kept = {k: recording[k] for k in ("joints", "joint_orientations", "joint_radii")}
    dqhand.write_recording(tmp_path / "copy.jsonl", recording["t"], side="right", **kept)
    again = dqhand.read_recording(tmp_path / "copy.jsonl")
    for key in recording:
        np.testing.assert_array_equal(again[key], recording[key])


def test_trackers_arrival_times_and_sides_per_record_round_trip(tmp_path):
    rng = np.random.default_rng(3)
    t = np.arange(5) * 0.01
    q = rng.normal(size=(5, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    p = rng.uniform(-1, 1, size=(5, 3))
    sides = ["left", "right", "left", "left", "right"]
    dqhand.write_recording(tmp_path / "tracker.jsonl", t, tracker_position=p, tracker_orientation=q, side=sides, arrival=t + 0.5)
    lines = json_lines(tmp_path / "tracker.jsonl")
    assert [line["hand"] for line in lines] == sides and lines[1]["tracker"]["p"] == pytest.approx(p[1].tolist())
    recording = dqhand.read_recording(tmp_path / "tracker.jsonl")
    assert set(recording) == {"t", "side", "arrival", "tracker_position", "tracker_orientation"}
    np.testing.assert_array_equal(recording["side"], sides)
    np.testing.assert_array_equal(recording["arrival"], t + 0.5)
    np.testing.assert_allclose(recording["tracker_position"], p, atol=1e-7)
    np.testing.assert_allclose(recording["tracker_orientation"], q, atol=1e-7)


def test_a_malformed_line_is_an_error_naming_the_file_and_line(tmp_path):
    good = (RECORDINGS / "gestures-landmarks.jsonl").read_text().splitlines()[0]
    path = tmp_path / "bad.jsonl"
    path.write_text(good + "\n\n" + '{"t": 0.1, "landmarks": [[0, 0, 0]]}\n')
    with pytest.raises(ValueError) as e:
        dqhand.read_recording(path)
    assert one_line(e).startswith(f"{path}: line 3: ")
    path.write_text(good + "\n" + json.dumps({"t": 0.1, "hand": "middle", "landmarks": [[0, 0, 0]] * 21}) + "\n")
    with pytest.raises(ValueError) as e:
        dqhand.read_recording(path)
    assert one_line(e).startswith(f"{path}: line 2: ") and "middle" in str(e.value)
    with pytest.raises(FileNotFoundError) as e:
        dqhand.read_recording(tmp_path / "missing.jsonl")
    assert one_line(e).startswith(str(tmp_path / "missing.jsonl"))
    with pytest.raises(ValueError, match="^side: "):
        dqhand.read_recording(path, side="up")


def test_what_the_reader_would_refuse_is_not_written(tmp_path):
    path = tmp_path / "refused.jsonl"
    t, joints = np.arange(2) * 0.1, np.zeros((2, 25, 3))
    quaternions = np.tile([0.0, 0.0, 0.0, 1.0], (2, 25, 1))
    quaternions[1, 3] = [0, 0, 0, 2]
    with pytest.raises(ValueError) as e:
        dqhand.write_recording(path, t, joints=joints, joint_orientations=quaternions)
    assert one_line(e).startswith("record 1: joint thumb-phalanx-distal: orientation") and "not a unit quaternion" in str(e.value)
    far = np.zeros((2, 21, 3))
    far[0, 5] = 1000
    with pytest.raises(ValueError, match="^record 0: landmark 5: position"):
        dqhand.write_recording(path, t, landmarks=far)
    with pytest.raises(ValueError, match="^record 1: t: -1.0 is negative|^record 1: t: -1 is negative"):
        dqhand.write_recording(path, [0.0, -1.0], landmarks=np.zeros((2, 21, 3)))
    assert not path.exists()
    with pytest.raises(ValueError, match=r"^landmarks: expected an array of shape \(2, 21, 3\)"):
        dqhand.write_recording(path, t, landmarks=np.zeros((3, 21, 3)))
    with pytest.raises(ValueError, match="^joints, landmarks, glove: "):
        dqhand.write_recording(path, t, joints=joints, landmarks=np.zeros((2, 21, 3)))
    with pytest.raises(ValueError, match="^tracker_position, tracker_orientation: "):
        dqhand.write_recording(path, t, tracker_position=np.zeros((2, 3)))
    with pytest.raises(ValueError, match="^joints, landmarks, glove, tracker_position: "):
        dqhand.write_recording(path, t)
    with pytest.raises(ValueError, match="^side: 1 sides for 2 records$"):
        dqhand.write_recording(path, t, landmarks=np.zeros((2, 21, 3)), side=["left"])
    with pytest.raises(ValueError, match=r'^side\[1\]: "up"'):
        dqhand.write_recording(path, t, landmarks=np.zeros((2, 21, 3)), side=["left", "up"])
    assert not path.exists()


# ---- Gestures ----


def replay_events(binary, path, *extra):
    out = cli(binary, "replay", "--input", path, "--gestures", *extra)
    return [(e["t"], e["event"], e["gesture"]) for e in map(json.loads, out.splitlines())]


@pytest.fixture(scope="module")
def replayed(binary):
    """`dqhand replay --gestures` of the bundled recordings."""
    return {kind: replay_events(binary, RECORDINGS / f"gestures-{kind}.jsonl") for kind in ("joints", "landmarks")}


@pytest.mark.parametrize("kind", ["joints", "landmarks"])
def test_a_recordings_events_are_the_command_lines(hand, replayed, kind):
    events = hand.recognize_recording(RECORDINGS / f"gestures-{kind}.jsonl")
    assert len(events) >= 10 and {e[2] for e in events} >= {"fist", "point", "victory"}
    assert events == replayed[kind]


@pytest.mark.parametrize("kind", ["joints", "landmarks"])
def test_arrays_of_a_recording_give_its_events(hand, replayed, kind):
    recording = dqhand.read_recording(RECORDINGS / f"gestures-{kind}.jsonl")
    assert hand.recognize(recording["t"], **{kind: recording[kind]}, side=recording["side"]) == replayed[kind]
    if len(set(recording["side"])) == 1:
        assert hand.recognize(recording["t"], **{kind: recording[kind]}, side=str(recording["side"][0])) == replayed[kind]


def test_definitions_from_a_file_and_a_configuration(hand, replayed, binary, tmp_path):
    path = RECORDINGS / "gestures-landmarks.jsonl"
    assert hand.recognize_recording(path, gestures=GESTURES_FILE) == replayed["landmarks"]
    (tmp_path / "slow.json").write_text(json.dumps({"angle_filter": {"min_cutoff": 0.05, "beta": 0.0, "d_cutoff": 1.0}}))
    slow = hand.recognize_recording(path, config=tmp_path / "slow.json")
    assert slow == replay_events(binary, path, "--config", tmp_path / "slow.json")
    assert slow != replayed["landmarks"], "a heavier filter moves the events"


def test_gesture_names_are_the_definitions(tmp_path):
    names = [g["name"] for g in json.loads(GESTURES_FILE.read_text())["gestures"]]
    assert dqhand.gesture_names() == names == dqhand.gesture_names(GESTURES_FILE)
    (tmp_path / "two.json").write_text(json.dumps({"min_hold_s": 0.1, "hysteresis": json.loads(GESTURES_FILE.read_text())["hysteresis"], "gestures": [{"name": "flat", "when": ["index.curl < 0.2"]}, {"name": "curled", "when": ["index.curl > 0.8"]}]}))
    assert dqhand.gesture_names(tmp_path / "two.json") == ["flat", "curled"]


def turning(a, b):
    """The rotation (4 × 4) that turns the unit direction a onto b."""
    v, c = np.cross(a, b), a @ b
    k = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    out = np.eye(4)
    out[:3, :3] = np.eye(3) + k + k @ k / (1 + c)
    return out


def test_held_template_poses_are_recognised_as_themselves(hand):
    """Each library gesture held for half a second, posed from `gesture_poses` (thumbs up with
    its thumb turned up), straight to the recogniser; then the same poses as tracked joints
    through the gesture loop."""
    poses = hand.gesture_poses()
    assert set(poses) <= set(dqhand.gesture_names()) and len(poses) == 11
    names = list(poses)
    frames = 30
    angles = np.repeat(np.stack([poses[n] for n in names]), frames, axis=0)
    wrists = np.tile(np.eye(4), (len(angles), 1, 1))
    joints = hand.joints(poses["thumbs_up"][None], np.eye(4)[None])[0]
    thumb = joints[dqhand.WEBXR_JOINTS.index("thumb-tip")] - joints[dqhand.WEBXR_JOINTS.index("thumb-phalanx-proximal")]
    up = names.index("thumbs_up")
    wrists[up * frames : (up + 1) * frames] = turning(thumb / np.linalg.norm(thumb), np.array([0.0, 1.0, 0.0]))
    times = np.arange(len(angles)) / 60
    events = hand.recognize(times, angles, wrists)
    starts = [e for e in events if e[1] == "start"]
    assert [e[2] for e in starts] == names
    for i, (t, _, name) in enumerate(starts):
        assert i * frames / 60 < t < i * frames / 60 + 0.2, (name, t)
    without = hand.recognize(times, angles)
    assert "thumbs_up" not in [e[2] for e in without], "the thumb must point up"
    tracked = hand.recognize(times, joints=hand.joints(angles, wrists))
    assert [e[2] for e in tracked if e[1] == "start"] == names


def test_bad_gesture_input_is_refused_naming_the_argument(hand, tmp_path):
    times = np.arange(3) / 30
    with pytest.raises(ValueError, match="^angles, landmarks, joints: give exactly one$"):
        hand.recognize(times)
    with pytest.raises(ValueError, match="^angles, landmarks, joints: give exactly one$"):
        hand.recognize(times, np.zeros((3, 23)), joints=np.zeros((3, 25, 3)))
    with pytest.raises(ValueError, match=r"^angles: 4 poses for 3 times$"):
        hand.recognize(times, np.zeros((4, 23)))
    with pytest.raises(ValueError, match=r"^angles: expected an array of shape \(B, 23\)"):
        hand.recognize(times, np.zeros((3, 22)))
    with pytest.raises(ValueError, match=r"^landmarks: expected an array of shape \(3, 21, 3\)"):
        hand.recognize(times, landmarks=np.zeros((3, 25, 3)))
    with pytest.raises(ValueError, match=r"^times\[1\]: -1 is negative$"):
        hand.recognize([0.0, -1.0, 2.0], np.zeros((3, 23)))
    with pytest.raises(ValueError, match="^side, config: "):
        hand.recognize(times, np.zeros((3, 23)), side="left")
    with pytest.raises(ValueError, match="^wrist: for angles"):
        hand.recognize(times, None, np.tile(np.eye(4), (3, 1, 1)), joints=np.zeros((3, 25, 3)))
    with pytest.raises(ValueError, match=r"^wrist\[0\]: not a rigid transform"):
        hand.recognize(times, np.zeros((3, 23)), np.zeros((3, 4, 4)))
    with pytest.raises(ValueError, match=r"^side: 2 sides for 3 records$"):
        hand.recognize(times, joints=np.zeros((3, 25, 3)), side=["left", "left"])
    with pytest.raises(FileNotFoundError):
        hand.recognize(times, np.zeros((3, 23)), gestures=tmp_path / "none.json")
    (tmp_path / "bad.json").write_text('{"gestures": [{"name": "x", "conditions": ["nonsense"]}]}')
    with pytest.raises(ValueError) as e:
        dqhand.gesture_names(tmp_path / "bad.json")
    assert one_line(e).startswith(str(tmp_path / "bad.json"))
    (tmp_path / "bad.jsonl").write_text('{"t": 0, "joints": 3}\n')
    with pytest.raises(ValueError) as e:
        hand.recognize_recording(tmp_path / "bad.jsonl")
    assert one_line(e).startswith(f"{tmp_path / 'bad.jsonl'}: line 1: ")


# ---- Realism metrics ----


@pytest.fixture(scope="module")
def report(binary):
    return json.loads(cli(binary, "metrics", "--json"))


def sweep_poses(hand, dof, degrees):
    angles = np.zeros((len(degrees), len(hand.dof_names)))
    angles[:, hand.dof_names.index(dof)] = np.radians(degrees)
    return angles


MEASURES = ["volume", "min_distance", "max_distance", "section_radius", "distortion_mean", "distortion_max"]


@pytest.mark.parametrize(
    "sweep, dof, joint",
    [
        ("index-pip", "index-finger-phalanx-intermediate.flex", "index-finger-phalanx-intermediate"),
        ("index-mcp", "index-finger-phalanx-proximal.flex", "index-finger-phalanx-proximal"),
    ],
)
def test_per_pose_measures_are_the_command_lines_sweeps(hand, report, sweep, dof, joint):
    swept = report["sweeps"][sweep]
    angles = sweep_poses(hand, dof, swept["values"])
    for method in ("lb", "qb", "dqb"):
        measured = hand.realism(angles, method=method, joint=joint, limits=False)
        for name in MEASURES:
            np.testing.assert_allclose(measured[name], swept[method][name], rtol=1e-5, atol=1e-6, err_msg=f"{sweep} {method} {name}")
    lb, dqb = (hand.realism(angles[-3:], method=m, joint=joint, limits=False) for m in ("lb", "dqb"))
    assert (lb["volume"] < dqb["volume"]).all(), "LB loses volume where DQB keeps it (the paper's claim)"


def test_the_fist_and_self_intersections_are_the_command_lines(hand, report):
    poses = hand.gesture_poses()
    fist = report["sweeps"]["fist"]
    measured = hand.realism(poses["fist"][None], method="dqb", joint="middle-finger-phalanx-intermediate", limits=False)
    for name in MEASURES:
        np.testing.assert_allclose(measured[name][0], fist["dqb"][name][-1], rtol=1e-5, atol=1e-6)
    rows = report["self_intersections"]["gestures"]
    names = [row["gesture"] for row in rows]
    angles = np.stack([poses[n] for n in names])
    for method in ("lb", "qb", "dqb"):
        counts = hand.realism(angles, method=method, self_intersections=True)["self_intersections"]
        assert counts.tolist() == [row[method] for row in rows], method


def test_the_report_is_the_command_lines(hand, report):
    ours = hand.realism_report()
    assert ours.keys() == report.keys() and ours["vertices"] == report["vertices"] == len(hand.rest_vertices)
    assert ours["self_intersections"] == report["self_intersections"]

    def same_contact(a, b, what):
        # A self-contact: depth, shared volume and vertex count (null where not measured).
        assert (a is None) == (b is None) and (a is None or a.keys() == b.keys()), what
        for key in a or {}:
            np.testing.assert_allclose(a[key], b[key], rtol=1e-5, atol=1e-6, err_msg=f"{what} {key}")

    same_contact(ours["self_contact"]["rest"], report["self_contact"]["rest"], "rest")
    assert [g["gesture"] for g in ours["self_contact"]["gestures"]] == [g["gesture"] for g in report["self_contact"]["gestures"]]
    for a, b in zip(ours["self_contact"]["gestures"], report["self_contact"]["gestures"]):
        for method in ("lb", "qb", "dqb"):
            same_contact(a[method], b[method], f"{a['gesture']} {method}")
    for name, sweep in report["sweeps"].items():
        for method in ("lb", "qb", "dqb"):
            for measure, values in sweep[method].items():
                if measure == "self_contact":
                    for k, (a, b) in enumerate(zip(ours["sweeps"][name][method][measure], values, strict=True)):
                        same_contact(a, b, f"{name} {method} frame {k}")
                    continue
                np.testing.assert_allclose(ours["sweeps"][name][method][measure], values, rtol=1e-5, atol=1e-6, err_msg=f"{name} {method} {measure}")


def segment_distance(x, a, b):
    """Distance of points x (N, 3) from the segment a → b."""
    ab = b - a
    s = np.clip(((x - a) @ ab) / (ab @ ab), 0, 1)
    return np.linalg.norm(x - (a + s[:, None] * ab), axis=1)


def volume(positions, faces):
    """Enclosed volume by the divergence theorem, double precision."""
    a, b, c = (positions[faces[:, i]].astype(np.float64) for i in range(3))
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6


def test_the_measures_agree_with_a_reference_from_their_definitions(hand):
    """Random poses with random wrists: volume, skin-to-bone distances, section radius and edge
    distortion recomputed here from `skin`, `joints` and the region's vertices."""
    joint = "index-finger-phalanx-intermediate"
    region = hand.joint_region(joint)
    a, j, c = (int(i) for i in region["joints"])
    assert [hand.joint_names[i] for i in (a, j, c)] == ["index-finger-phalanx-proximal", joint, "index-finger-phalanx-distal"]
    vertices = region["vertices"]
    assert 50 < len(vertices) < len(hand.rest_vertices) / 4
    angles, wrists = random_angles(hand, 4, seed=7), random_wrists(4, seed=8)
    measured = hand.realism(angles, wrists, method="lb", joint=joint)
    posed, joints = hand.skin(angles, wrists, "lb"), hand.joints(angles, wrists)
    rest, faces = hand.rest_vertices, hand.faces.astype(np.int64)
    names = dqhand.WEBXR_JOINTS
    bind = hand.joints(np.zeros((1, len(hand.dof_names))))[0]  # the built-in hand is bound at rest
    np.testing.assert_allclose(hand.skinning_transforms(np.zeros((1, len(hand.dof_names))))[0], np.tile(np.eye(4), (len(names), 1, 1)), atol=1e-5)
    at = [names.index(hand.joint_names[i]) for i in (a, j, c)]
    region_vertices = np.zeros(len(rest), bool)
    region_vertices[vertices] = True
    edges = np.unique(np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1), axis=0)
    edges = edges[region_vertices[edges].all(axis=1)]
    rest_lengths = np.linalg.norm(rest[edges[:, 0]] - rest[edges[:, 1]], axis=1)
    rest_distance = np.minimum(segment_distance(rest[vertices], *bind[at[:2]]), segment_distance(rest[vertices], *bind[at[1:]]))
    for b in range(4):
        x, p = posed[b], joints[b][at]
        assert measured["volume"][b] == pytest.approx(volume(x, faces) / volume(rest, faces), abs=1e-5)
        ratio = np.minimum(segment_distance(x[vertices], p[0], p[1]), segment_distance(x[vertices], p[1], p[2])) / rest_distance
        assert measured["min_distance"][b] == pytest.approx(ratio.min(), rel=1e-4)
        assert measured["max_distance"][b] == pytest.approx(ratio.max(), rel=1e-4)
        axis = (p[2] - p[1]) / np.linalg.norm(p[2] - p[1])
        d = x[vertices] - p[1]
        radial = np.linalg.norm(d - np.outer(d @ axis, axis), axis=1)
        assert measured["section_radius"][b] == pytest.approx(radial.min() / region["min_radius"], rel=1e-4)
        change = np.abs(np.linalg.norm(x[edges[:, 0]] - x[edges[:, 1]], axis=1) - rest_lengths) / rest_lengths
        assert measured["distortion_mean"][b] == pytest.approx(change.mean(), rel=1e-4)
        assert measured["distortion_max"][b] == pytest.approx(change.max(), rel=1e-4)


def test_bad_metric_arguments_are_refused(hand):
    angles = np.zeros((1, len(hand.dof_names)))
    with pytest.raises(ValueError) as e:
        hand.realism(angles, joint="index-knuckle")
    assert one_line(e).startswith('unknown joint "index-knuckle"; valid: wrist, ')
    with pytest.raises(ValueError, match='^next: joint "wrist" has 5 children'):
        hand.realism(angles, joint="wrist")
    with pytest.raises(ValueError, match='^unknown skinning method "xyz"; valid: lb, qb, dqb, cor$'):
        hand.realism(angles, method="xyz")
    with pytest.raises(ValueError, match=r"^angles: expected an array of shape \(B, 23\)"):
        hand.realism(np.zeros((1, 5)))
    assert all(len(v) == 0 for v in hand.realism(np.zeros((0, 23))).values())


# ---- glTF export ----


def test_the_exported_hand_loads_back_as_the_same_hand(hand, binary, tmp_path):
    hand.export_gltf(tmp_path / "hand.glb")
    assert (tmp_path / "hand.glb").read_bytes()[:4] == b"glTF"
    cli(binary, "hand", "--out", tmp_path / "cli.glb")
    assert (tmp_path / "hand.glb").read_bytes() == (tmp_path / "cli.glb").read_bytes(), "dqhand hand writes the same file"
    loaded = dqhand.Hand.load(tmp_path / "hand.glb")
    assert loaded.joint_names == hand.joint_names and loaded.dof_names == hand.dof_names
    np.testing.assert_array_equal(loaded.faces, hand.faces)
    np.testing.assert_allclose(loaded.rest_vertices, hand.rest_vertices, atol=1e-7)
    for ours, theirs in zip(loaded.influences, hand.influences):
        np.testing.assert_allclose(ours, theirs, atol=1e-6)
    angles, wrists = random_angles(hand, 3, seed=9), random_wrists(3, seed=10)
    np.testing.assert_allclose(loaded.skin(angles, wrists), hand.skin(angles, wrists), atol=1e-6)
    left = dqhand.Hand.builtin(length=0.17, side="left", vertices=3000)
    left.export_gltf(tmp_path / "left.glb")
    np.testing.assert_allclose(dqhand.Hand.load(tmp_path / "left.glb").joints(angles), left.joints(angles), atol=1e-6)


def read_ply(path):
    """Positions and normals of a binary PLY that `dqhand skin` writes (x y z nx ny nz)."""
    data = Path(path).read_bytes()
    header, body = data.split(b"end_header\n", 1)
    count = int(next(line.split()[2] for line in header.decode().splitlines() if line.startswith("element vertex")))
    return np.frombuffer(body[: 24 * count], dtype="<f4").reshape(count, 6)


def test_a_posed_mesh_is_the_command_lines(hand, binary, tmp_path):
    angles = random_angles(hand, 1, seed=11)[0]
    pose = {"model": "full", "angles_deg": dict(zip(hand.dof_names, np.degrees(angles).tolist()))}
    (tmp_path / "pose.json").write_text(json.dumps(pose))
    for method in ("dqb", "lb"):
        cli(binary, "skin", "--pose", tmp_path / "pose.json", "--method", method, "--out", tmp_path / "cli.ply")
        hand.export_posed(tmp_path / "ours.ply", angles, method=method)
        ours, theirs = read_ply(tmp_path / "ours.ply"), read_ply(tmp_path / "cli.ply")
        np.testing.assert_allclose(ours, theirs, atol=2e-6)
        np.testing.assert_allclose(ours[:, :3], hand.skin(angles[None], method=method)[0], atol=1e-7)
    wrist = random_wrists(1, seed=12)[0]
    hand.export_posed(tmp_path / "moved.ply", angles, wrist)
    np.testing.assert_allclose(read_ply(tmp_path / "moved.ply")[:, :3], hand.skin(angles[None], wrist[None])[0], atol=1e-7)
    hand.export_posed(tmp_path / "posed.obj", angles)
    assert sum(line.startswith("v ") for line in (tmp_path / "posed.obj").read_text().splitlines()) == len(hand.rest_vertices)
    hand.export_posed(tmp_path / "posed.glb", angles)
    assert (tmp_path / "posed.glb").read_bytes()[:4] == b"glTF"


def test_bad_export_arguments_are_refused(hand, tmp_path):
    with pytest.raises(ValueError, match=r"^path: .*hand\.gltf: .*\.glb$"):
        hand.export_gltf(tmp_path / "hand.gltf")
    with pytest.raises(FileNotFoundError):
        hand.export_gltf(tmp_path / "no/such/dir/hand.glb")
    with pytest.raises(ValueError, match="unknown output format"):
        hand.export_posed(tmp_path / "posed.stl", np.zeros(23))
    with pytest.raises(ValueError, match=r"^angles: expected an array of shape \(23\)"):
        hand.export_posed(tmp_path / "posed.ply", np.zeros((1, 23)))
    scaled = np.eye(4)
    scaled[0, 0] = 2
    with pytest.raises(ValueError, match="^wrist: not a rigid transform"):
        hand.export_posed(tmp_path / "posed.ply", np.zeros(23), scaled)
    assert not (tmp_path / "posed.ply").exists()


def test_the_contact_pass_moves_a_fists_skin_and_leaves_the_open_hand(hand):
    poses = hand.gesture_poses()
    angles = np.stack([poses["open_palm"], poses["fist"]])
    plain = hand.skin(angles)
    passed, normals = hand.skin(angles, normals=True, contact_pass=True)
    np.testing.assert_array_equal(passed[0], plain[0], err_msg="the open hand has no skin inside skin: nothing moves")
    moved = np.linalg.norm(passed[1] - plain[1], axis=1)
    # The fist's fingertips and thumb come out of the palm and the fingers: some hundreds of
    # vertices, by millimetres; the rest of the skin stays.
    assert 50 < (moved > 0).sum() < len(moved) // 10, (moved > 0).sum()
    assert moved.max() < 0.01, moved.max()
    np.testing.assert_allclose(np.linalg.norm(normals, axis=2), 1, atol=1e-4)

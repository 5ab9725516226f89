"""dqhand's Python API, on the installed wheel.

The skin is held to a reference written here from the definitions (Kavan et al. 2008: dual
quaternions aligned with the heaviest influence, blended, normalised; linear blending of the
matrices; Le and Hodgins 2016: the blended quaternion's turn about each vertex's centre of
rotation, moved as linear blending moves the centre, and the centres themselves), in double
precision with NumPy, sharing no code with the library; and to the Rust
command line's output of the same poses (`dqhand skin`, the binary in $DQHAND_BIN). The WebXR
generic hand, a glTF made elsewhere, is skinned and held to the same reference.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import dqhand
from wrists import random_wrists

ROOT = Path(__file__).resolve().parents[3]
GENERIC_HAND = ROOT / "third_party/node_modules/@webxr-input-profiles/assets/dist/profiles/generic-hand/right.glb"


@pytest.fixture(scope="module")
def hand():
    return dqhand.Hand.builtin()


@pytest.fixture(scope="module")
def generic():
    if not GENERIC_HAND.exists():
        pytest.fail(f"{GENERIC_HAND} is missing: `make assets` installs it")
    return dqhand.Hand.load(GENERIC_HAND)


def random_angles(hand, count, seed, spread=1.0):
    """Angles within each joint's range (``spread`` > 1 reaches beyond it), radians."""
    rng = np.random.default_rng(seed)
    low, high = hand.limits[:, 0], hand.limits[:, 1]
    middle, half = (low + high) / 2, (high - low) / 2 * spread
    return (middle + half * rng.uniform(-1, 1, size=(count, len(low)))).astype(np.float64)


# ---- The reference, from the definitions. ----


def quaternion(r):
    """The unit quaternion (w, x, y, z) of a rotation matrix (Shepperd's method)."""
    trace = np.trace(r)
    k = int(np.argmax([trace, r[0, 0], r[1, 1], r[2, 2]]))
    if k == 0:
        s = 2 * np.sqrt(1 + trace)
        return np.array([s / 4, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s])
    i, j, l = [(0, 1, 2), (1, 2, 0), (2, 0, 1)][k - 1]
    s = 2 * np.sqrt(1 + r[i, i] - r[j, j] - r[l, l])
    q = np.zeros(4)
    q[0] = (r[l, j] - r[j, l]) / s
    q[1 + i] = s / 4
    q[1 + j] = (r[i, j] + r[j, i]) / s
    q[1 + l] = (r[i, l] + r[l, i]) / s
    return q


def product(a, b):
    """Hamilton products of quaternions (w, x, y, z), along the last axis."""
    w1, v1 = a[..., :1], a[..., 1:]
    w2, v2 = b[..., :1], b[..., 1:]
    return np.concatenate([w1 * w2 - np.sum(v1 * v2, -1, keepdims=True), w1 * v2 + w2 * v1 + np.cross(v1, v2)], -1)


def linear_blend(points, joints, weights, transforms):
    """``points`` (V, 3) moved by each vertex's blended matrix."""
    homogeneous = np.concatenate([points, np.ones((len(points), 1))], 1)
    blended = np.einsum("vk,vkij->vij", weights, transforms[joints])
    return np.einsum("vij,vj->vi", blended, homogeneous)[:, :3]


def reference_skin(rest, joints, weights, transforms, method, centres=None):
    """Positions of ``rest`` (V, 3) skinned by ``transforms`` (J, 4, 4) with the influences
    (``centres`` (V, 3), the centres of rotation, for "cor")."""
    transforms = transforms.astype(np.float64)
    if method == "lb":
        return linear_blend(rest, joints, weights, transforms)
    real = np.array([quaternion(t[:3, :3]) for t in transforms])
    translation = np.concatenate([np.zeros((len(transforms), 1)), transforms[:, :3, 3]], 1)
    dual = 0.5 * product(translation, real)
    # Influences come heaviest first: the first is the pivot the others' signs align with.
    r, d = real[joints], dual[joints]
    signs = np.where(np.sum(r * r[:, :1], -1) < 0, -1.0, 1.0)
    w = (weights * signs)[..., None]
    r, d = np.sum(w * r, 1), np.sum(w * d, 1)
    length = np.linalg.norm(r, axis=1, keepdims=True)
    r, d = r / length, d / length
    conjugate = r * np.array([1, -1, -1, -1])
    if method == "cor":
        # v' = q (v - p*) q* + LB(p*): the blended turn about the centre, carried as LB carries it.
        centres = centres.astype(np.float64)
        offset = np.concatenate([np.zeros((len(rest), 1)), rest - centres], 1)
        return product(product(r, offset), conjugate)[:, 1:] + linear_blend(centres, joints, weights, transforms)
    point = np.concatenate([np.zeros((len(rest), 1)), rest], 1)
    moved = product(product(r, point), conjugate)[:, 1:]
    return moved + 2 * product(d, conjugate)[:, 1:]


def reference_centres(rest, faces, joints, weights, vertices, sigma=0.1):
    """The centres of rotation of ``vertices`` from Le and Hodgins' definition: the mean of
    every triangle's centroid weighted by its area and by the similarity of its mean weights
    to the vertex's, s(a, b) = sum over joints j != k of a_j a_k b_j b_k exp(-(a_j b_k - a_k b_j)^2 / sigma^2)
    (only the vertex's own joints can make a term nonzero); a vertex no triangle is like keeps
    its rest position."""
    count = int(joints.max()) + 1
    dense = np.zeros((len(rest), count))
    np.add.at(dense, (np.arange(len(rest))[:, None], joints), weights)
    dense /= dense.sum(1, keepdims=True)
    a, b, c = rest[faces[:, 0]], rest[faces[:, 1]], rest[faces[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    centroid = (a + b + c) / 3
    mean = dense[faces].mean(1)
    centres = []
    for v in vertices:
        own = np.nonzero(dense[v])[0]
        s = np.zeros(len(faces))
        for j in own:
            for k in own:
                if j != k:
                    wj, wk = dense[v, j], dense[v, k]
                    gap = wj * mean[:, k] - wk * mean[:, j]
                    s += wj * wk * mean[:, j] * mean[:, k] * np.exp(-gap * gap / sigma**2)
        total = np.sum(s * area)
        centres.append(np.sum((s * area)[:, None] * centroid, 0) / total if total > 0 else rest[v])
    return np.array(centres)


def check_against_reference(hand, angles, wrists, method):
    joints, weights = hand.influences
    skinned = hand.skin(angles, wrists, method=method)
    transforms = hand.skinning_transforms(angles, wrists)
    size = np.ptp(hand.rest_vertices, axis=0).max()
    centres = hand.centres_of_rotation if method == "cor" else None
    rest = hand.rest_vertices.astype(np.float64)
    worst = max(np.abs(skinned[b] - reference_skin(rest, joints, weights, transforms[b], method, centres)).max() for b in range(len(angles)))
    assert worst < 1e-5 * size / 0.2, f"{method}: {worst} m from the reference"
    return worst


# ---- The tests. ----


def test_the_builtin_hand_has_its_mesh_joints_and_angles(hand):
    v = len(hand.rest_vertices)
    assert hand.rest_vertices.shape == (v, 3) and hand.rest_vertices.dtype == np.float32
    assert hand.faces.shape[1] == 3 and hand.faces.max() < v
    assert sorted(hand.joint_names) == sorted(dqhand.WEBXR_JOINTS)
    assert len(hand.dof_names) == 23 and hand.limits.shape == (23, 2)
    assert np.all(hand.limits[:, 0] <= hand.limits[:, 1])
    joints, weights = hand.influences
    assert joints.shape == weights.shape and joints.shape[0] == v
    np.testing.assert_allclose(weights.sum(1), 1, atol=1e-5)
    # The hand is metres-sized: 19 cm from the wrist crease to the middle fingertip.
    assert 0.15 < np.ptp(hand.rest_vertices, axis=0).max() < 0.3
    assert "Hand" in repr(hand)


@pytest.mark.parametrize("method", ["dqb", "lb", "cor"])
def test_the_skin_matches_a_reference_from_the_definitions(hand, method):
    angles = random_angles(hand, 6, seed=1)
    check_against_reference(hand, angles, random_wrists(6, seed=2), method)


def test_the_references_tell_dqb_from_lb(hand):
    """The two references differ by millimetres on these poses: the comparisons above can fail."""
    angles, wrists = random_angles(hand, 2, seed=1), random_wrists(2, seed=2)
    joints, weights = hand.influences
    transforms = hand.skinning_transforms(angles, wrists)
    rest = hand.rest_vertices.astype(np.float64)
    gap = np.abs(reference_skin(rest, joints, weights, transforms[0], "dqb") - reference_skin(rest, joints, weights, transforms[0], "lb")).max()
    assert gap > 1e-3, gap
    cor = reference_skin(rest, joints, weights, transforms[0], "cor", hand.centres_of_rotation)
    assert np.abs(cor - reference_skin(rest, joints, weights, transforms[0], "dqb")).max() > 1e-4


@pytest.mark.parametrize("which", ["builtin", "generic"])
def test_the_centres_of_rotation_are_the_definitions(hand, generic, which):
    """Forty blending vertices and five rigid ones of each hand, the WebXR generic hand (made
    elsewhere) among them, against the definition summed over every triangle."""
    h = hand if which == "builtin" else generic
    joints, weights = h.influences
    rest = h.rest_vertices.astype(np.float64)
    centres = h.centres_of_rotation
    assert centres.shape == rest.shape and centres.dtype == np.float32
    rng = np.random.default_rng(5)
    blending = np.nonzero((weights > 0).sum(1) >= 2)[0]
    rigid = np.nonzero((weights > 0).sum(1) == 1)[0]
    assert len(blending) >= 40 and len(rigid) >= 5
    picked = np.concatenate([rng.choice(blending, 40, replace=False), rng.choice(rigid, 5, replace=False)])
    expected = reference_centres(rest, h.faces.astype(np.int64), joints, weights, picked)
    size = np.ptp(rest, axis=0).max()
    worst = np.abs(centres[picked] - expected).max()
    assert worst < 1e-5 * size / 0.2, f"{which}: a centre {worst} m from the definition"
    # Blending vertices' centres are off the surface, inside the hand: not their rest positions.
    assert np.median(np.linalg.norm(centres[blending] - rest[blending], axis=1)) > 1e-3


def test_a_wrist_turned_almost_180_degrees_still_matches(hand):
    """Near 180° the joints' quaternions sit near the w = 0 equator, where their signs come out
    either way: only the alignment with the heaviest influence keeps the blend right."""
    wrists = np.tile(np.eye(4), (3, 1, 1))
    for b, axis in enumerate(np.eye(3)):
        angle = np.radians(179.9)
        k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        wrists[b, :3, :3] = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
    check_against_reference(hand, random_angles(hand, 3, seed=10), wrists, "dqb")


def test_the_papers_joint_model_has_18_angles_and_matches_the_reference():
    paper = dqhand.Hand.builtin(vertices=3000, model="paper")
    assert len(paper.dof_names) == 18 and paper.limits.shape == (18, 2)
    check_against_reference(paper, random_angles(paper, 3, seed=11), random_wrists(3, seed=12), "dqb")


def test_a_hand_made_elsewhere_loads_and_matches_the_reference(generic):
    """The WebXR input profiles' generic hand (glTF): its own mesh, weights and joint frames."""
    assert len(generic.rest_vertices) > 1000
    angles = random_angles(generic, 4, seed=3)
    check_against_reference(generic, angles, random_wrists(4, seed=4), "dqb")
    check_against_reference(generic, angles, random_wrists(4, seed=4), "cor")
    # A bent finger moves its tip and not the wrist.
    bent = np.zeros((1, len(generic.dof_names)))
    bent[0, generic.dof_names.index("index-finger-phalanx-intermediate.flex")] = np.radians(90)
    rest, moved = generic.joints(np.zeros_like(bent)), generic.joints(bent)
    tip = dqhand.WEBXR_JOINTS.index("index-finger-tip")
    assert np.linalg.norm(moved[0, tip] - rest[0, tip]) > 0.01
    assert np.linalg.norm(moved[0, 0] - rest[0, 0]) < 1e-6


def read_ply(path):
    """Positions of a binary PLY that `dqhand skin` writes (x y z nx ny nz per vertex)."""
    data = Path(path).read_bytes()
    header, body = data.split(b"end_header\n", 1)
    count = int(next(line.split()[2] for line in header.decode().splitlines() if line.startswith("element vertex")))
    return np.frombuffer(body[: 24 * count], dtype="<f4").reshape(count, 6)[:, :3]


@pytest.mark.parametrize("method", ["dqb", "cor"])
def test_the_same_poses_give_the_command_lines_vertices(hand, tmp_path, method):
    binary = os.environ.get("DQHAND_BIN")
    if not binary:
        pytest.fail("DQHAND_BIN must name the dqhand binary (make test sets it)")
    angles = random_angles(hand, 3, seed=5)
    wrists = random_wrists(3, seed=6)
    skinned = hand.skin(angles, wrists, method)
    for b in range(3):
        rotation = quaternion(wrists[b, :3, :3])
        pose = {
            "model": "full",
            "wrist": {"translation": wrists[b, :3, 3].tolist(), "rotation": [*rotation[1:], rotation[0]]},
            "angles_deg": dict(zip(hand.dof_names, np.degrees(angles[b]).tolist())),
        }
        (tmp_path / "pose.json").write_text(json.dumps(pose))
        subprocess.run([binary, "skin", "--pose", str(tmp_path / "pose.json"), "--method", method, "--out", str(tmp_path / "posed.ply")], check=True, capture_output=True)
        np.testing.assert_allclose(skinned[b], read_ply(tmp_path / "posed.ply"), atol=2e-6)


def test_normals_are_unit_and_keypoints_are_mediapipes_joints(hand):
    angles = random_angles(hand, 2, seed=7)
    positions, normals = hand.skin(angles, normals=True)
    assert positions.shape == normals.shape == (2, len(hand.rest_vertices), 3)
    np.testing.assert_allclose(np.linalg.norm(normals, axis=2), 1, atol=1e-4)
    np.testing.assert_array_equal(positions, hand.skin(angles))
    joints, keypoints = hand.joints(angles), hand.keypoints(angles)
    assert joints.shape == (2, 25, 3) and keypoints.shape == (2, 21, 3)
    # MediaPipe's landmarks at the WebXR joints: the thumb's CMC, MCP and IP at the bases of
    # its metacarpal, proximal and distal bones; a finger's MCP, PIP and DIP at its phalanges'.
    thumb = ["thumb-metacarpal", "thumb-phalanx-proximal", "thumb-phalanx-distal", "thumb-tip"]
    fingers = [[f"{f}-finger-phalanx-{p}" for p in ["proximal", "intermediate", "distal"]] + [f"{f}-finger-tip"] for f in ["index", "middle", "ring", "pinky"]]
    names = ["wrist", *thumb, *sum(fingers, [])]
    assert dqhand.MEDIAPIPE_KEYPOINTS[8] == "INDEX_FINGER_TIP" and names[8] == "index-finger-tip"
    np.testing.assert_array_equal(keypoints, joints[:, [dqhand.WEBXR_JOINTS.index(n) for n in names]])


def test_limits_clamp_unless_switched_off(hand):
    beyond = random_angles(hand, 2, seed=8, spread=3.0)
    clamped = np.clip(beyond, hand.limits[:, 0], hand.limits[:, 1])
    np.testing.assert_allclose(hand.skin(beyond), hand.skin(clamped), atol=1e-6)
    assert np.abs(hand.skin(beyond, limits=False) - hand.skin(clamped)).max() > 1e-3


def test_float32_float64_lists_and_any_layout_give_the_same_skin(hand):
    angles = random_angles(hand, 2, seed=9)
    wrists = random_wrists(2, seed=9)
    expected = hand.skin(angles, wrists)
    np.testing.assert_array_equal(expected, hand.skin(angles.tolist(), wrists.tolist()))
    np.testing.assert_allclose(expected, hand.skin(np.asfortranarray(angles), wrists.astype(np.float32)), atol=1e-6)
    np.testing.assert_array_equal(expected, hand.skin(np.repeat(angles, 2, axis=1)[:, ::2], wrists))
    np.testing.assert_allclose(expected, hand.skin(angles.astype(np.float32), wrists), atol=1e-6)
    assert hand.skin(np.zeros((0, 23))).shape == (0, len(hand.rest_vertices), 3)


def test_a_left_hand_is_built_as_a_left_hand():
    left = dqhand.Hand.builtin(side="left", vertices=3000)
    right = dqhand.Hand.builtin(side="right", vertices=3000)
    thumb = dqhand.WEBXR_JOINTS.index("thumb-tip")
    rest = np.zeros((1, 23))
    # Palm down, fingers along -Z: the left thumb on +X, the right one on -X.
    assert left.joints(rest)[0, thumb, 0] > 0 > right.joints(rest)[0, thumb, 0]


@pytest.mark.parametrize(
    "call, error, words",
    [
        (lambda h: h.skin(np.zeros((2, 5))), ValueError, ["angles", "(B, 23)", "(2, 5)"]),
        (lambda h: h.skin(np.zeros(23)), ValueError, ["angles", "(B, 23)"]),
        (lambda h: h.skin([["a"] * 23]), ValueError, ["angles"]),
        (lambda h: h.skin(np.full((1, 23), np.nan)), ValueError, ["angles", "not finite"]),
        (lambda h: h.skin(np.zeros((1, 23)), method="cubic"), ValueError, ["cubic", "lb, qb, dqb, cor"]),
        (lambda h: h.skin(np.zeros((2, 23)), wrist=np.zeros((1, 4, 4))), ValueError, ["wrist", "(2, 4, 4)", "(1, 4, 4)"]),
        (lambda h: h.skin(np.zeros((1, 23)), wrist=np.eye(4)), ValueError, ["wrist", "(1, 4, 4)", "got shape (4, 4)"]),
        (lambda h: h.skin(np.zeros((1, 23)), wrist=np.eye(4)[None] * 2), ValueError, ["wrist[0]", "rigid"]),
        (lambda h: h.skin(np.zeros((1, 23)), wrist=np.diag([2.0, 2.0, 2.0, 1.0])[None]), ValueError, ["wrist[0]", "rigid"]),
        (lambda h: h.skin(np.zeros((1, 23)), wrist=np.diag([-1.0, 1.0, 1.0, 1.0])[None]), ValueError, ["wrist[0]", "mirror"]),
        (lambda h: h.skin(np.zeros((1, 23)), wrist=np.array([[[1, 0.6, 0, 0], [0, 0.8, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]])), ValueError, ["wrist[0]", "shear"]),
        (lambda h: h.skin(np.full((1, 23), np.inf)), ValueError, ["angles", "inf", "not finite"]),
        (lambda h: h.skin(np.full((1, 23), 1e39)), ValueError, ["angles", "of item 0", "does not fit float32"]),
        (lambda h: h.skin(np.zeros((1, 23)), normals=None), TypeError, []),
        (lambda h: h.skin(np.zeros((1, 23)), "dqb", "dqb", True), TypeError, []),
        (lambda h: dqhand.Hand.builtin(side="middle"), ValueError, ["side", "middle"]),
        (lambda h: dqhand.Hand.builtin(model="hooves"), ValueError, ["hooves"]),
        (lambda h: dqhand.Hand.load("no/such/hand.glb"), FileNotFoundError, ["no/such/hand.glb"]),
    ],
)
def test_bad_arguments_raise_one_line_errors_naming_them(hand, call, error, words):
    with pytest.raises(error) as raised:
        call(hand)
    message = str(raised.value)
    assert "\n" not in message
    for word in words:
        assert word in message, message


def test_files_that_are_not_hands_raise_errors_naming_them(tmp_path):
    bad = tmp_path / "hand.glb"
    bad.write_bytes(b"not a glTF file")
    with pytest.raises(ValueError, match="hand.glb"):
        dqhand.Hand.load(bad)
    with pytest.raises(OSError, match=str(tmp_path)):
        dqhand.Hand.load(tmp_path)
    # The generic hand with a joint the joint model moves renamed: the file and the joint named.
    renamed = tmp_path / "renamed.glb"
    renamed.write_bytes(glb_with_renamed_node(GENERIC_HAND.read_bytes(), "index-finger-phalanx-intermediate", "index-middle"))
    with pytest.raises(ValueError) as raised:
        dqhand.Hand.load(renamed)
    assert "renamed.glb" in str(raised.value) and "index-finger-phalanx-intermediate" in str(raised.value), raised.value


def glb_with_renamed_node(glb, old, new):
    """A binary glTF with the node named ``old`` renamed ``new`` (its JSON chunk rewritten)."""
    length = int.from_bytes(glb[12:16], "little")
    document = json.loads(glb[20 : 20 + length])
    for node in document["nodes"]:
        if node.get("name") == old:
            node["name"] = new
    text = json.dumps(document).encode()
    text += b" " * (-len(text) % 4)
    rest = glb[20 + length :]
    body = len(text).to_bytes(4, "little") + b"JSON" + text + rest
    return glb[:4] + glb[4:8] + (12 + len(body)).to_bytes(4, "little") + body


def test_the_bench_measures_every_row_in_one_run():
    binary = os.environ.get("DQHAND_BIN")
    if not binary:
        pytest.fail("DQHAND_BIN must name the dqhand binary (make test sets it)")
    run = subprocess.run([sys.executable, "-m", "dqhand.bench", "--poses", "4", "--repeats", "1", "--json", "--dqhand", binary], check=True, capture_output=True, text=True)
    report = json.loads(run.stdout)
    names = [r["what"] for r in report["rows"]]
    assert any(n.startswith("Python API, DQB") for n in names) and any(n.startswith("NumPy LB") for n in names)
    assert any(n.startswith("dqhand skin --poses") for n in names) and any(n.startswith("dqhand bench") for n in names)
    assert all(r["us_per_pose"] > 0 for r in report["rows"]) and report["python_over_rust_kernel"] > 0 and report["skipped"] is None
    bad = subprocess.run([sys.executable, "-m", "dqhand.bench", "--poses", "0"], capture_output=True, text=True)
    assert bad.returncode == 2 and "--poses and --repeats must be at least 1" in bad.stderr

"""The software rasterizer against ray casting, and `dqhand.synth` on a local Ray with 2 CPUs:
20,000 samples, their counts, schema and values, the same as a one-process run, a killed
worker's shard made again, bad arguments."""

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest
import ray

import dqhand
from dqhand import synth


def ray_cast_depth(vertices, faces, k, pose, width, height):
    """Depth by ray casting (Möller–Trumbore): each pixel centre's ray from the camera against
    every triangle, the nearest hit's z. Shares nothing with the rasterizer's edge functions."""
    camera = vertices @ pose[:3, :3].T + pose[:3, 3]
    a, b, c = camera[faces[:, 0]], camera[faces[:, 1]], camera[faces[:, 2]]
    u, v = np.meshgrid(np.arange(width), np.arange(height))
    rays = np.stack([u.ravel(), v.ravel(), np.ones(u.size)], axis=1) @ np.linalg.inv(k).T  # z = 1
    e1, e2 = b - a, c - a
    p = np.cross(rays[:, None, :], e2[None])
    det = np.einsum("tk,ptk->pt", e1, p)
    ok = np.abs(det) > 1e-15
    inv = np.where(ok, 1 / np.where(ok, det, 1), 0)
    s = -a[None]
    bu = np.einsum("ptk,ptk->pt", s, p) * inv
    q = np.cross(s, e1[None])
    bv = np.einsum("pk,ptk->pt", rays, q) * inv
    t = np.einsum("tk,ptk->pt", e2, q) * inv
    hit = ok & (bu >= 0) & (bv >= 0) & (bu + bv <= 1) & (t > 0)
    depth = np.where(hit, t, np.inf).min(axis=1)  # t along a ray of unit z is the depth
    return np.where(np.isfinite(depth), depth, 0).reshape(height, width)


def test_render_depth_matches_ray_casting():
    hand = dqhand.Hand.builtin(vertices=1000)
    rng = np.random.default_rng(3)
    angles = rng.uniform(hand.limits[:, 0], hand.limits[:, 1], size=(4, len(hand.dof_names)))
    vertices = hand.skin(angles).astype(np.float64)
    size = 40
    k = np.array([[48.0, 1.5, 19.5], [0.8, 52.0, 20.1], [0, 0, 1]])  # skewed, every term used
    poses = synth._look_at(rng, vertices.mean(axis=1), np.full(4, 0.3))
    depth = dqhand.render_depth(vertices, hand.faces, np.tile(k, (4, 1, 1)), poses, size, size)
    assert depth.shape == (4, size, size) and depth.dtype == np.float32
    for b in range(4):
        reference = ray_cast_depth(vertices[b], hand.faces.astype(np.int64), k, poses[b], size, size)
        # Pixel centres on a triangle's edge may fall either way: a few pixels at most.
        assert np.count_nonzero((depth[b] > 0) != (reference > 0)) <= 2, b
        both = (depth[b] > 0) & (reference > 0)
        assert both.sum() > 50
        np.testing.assert_allclose(depth[b][both], reference[both], atol=2e-6, rtol=1e-5)


def test_render_depth_bad_arguments():
    v = np.zeros((1, 3, 3))
    k, pose = np.eye(3)[None], np.eye(4)[None]
    with pytest.raises(ValueError, match=r"^faces: index 3 of triangle 0 is not a vertex \(there are 3\)$"):
        dqhand.render_depth(v, [[0, 1, 3]], k, pose, 8, 8)
    with pytest.raises(ValueError, match=r"^intrinsics: expected an array of shape \(1, 3, 3\)"):
        dqhand.render_depth(v, [[0, 1, 2]], np.eye(3), pose, 8, 8)
    with pytest.raises(ValueError, match=r"^width: 0 pixels is not an image side"):
        dqhand.render_depth(v, [[0, 1, 2]], k, pose, 0, 8)
    with pytest.raises(ValueError, match=r"^faces: expected integers of shape \(F, 3\) \(vertex indices\), got float64$"):
        dqhand.render_depth(v, [[0.0, 1.0, 2.0]], k, pose, 8, 8)
    with pytest.raises(ValueError, match=r"^extrinsics\[0\]: not a rigid or affine transform"):
        dqhand.render_depth(v, [[0, 1, 2]], k, np.ones((1, 4, 4)), 8, 8)


@pytest.fixture(scope="module")
def local_ray():
    ray.init(num_cpus=2, include_dashboard=False, runtime_env={"env_vars": {"RAYON_NUM_THREADS": "1"}}, logging_level="warning")
    yield
    ray.shutdown()


def column(table, name, width=None):
    values = table[name].combine_chunks()
    if width is None:
        return values.to_numpy(zero_copy_only=False)
    return values.flatten().to_numpy(zero_copy_only=False).reshape(table.num_rows, width)


def one_process_shard(settings, shard):
    """The shard as this process makes it, no Ray involved."""
    return pa.concat_tables(synth._table(chunk) for chunk in synth.make_shard(settings, shard))


def test_twenty_thousand_samples_on_ray(local_ray, tmp_path):
    out = tmp_path / "set"
    summary = synth.synth(20_000, out, seed=7, image_size=64, shard_size=2_000, ball_share=0.25)
    assert summary["samples"] == 20_000 and summary["shards"] == 10
    assert sorted(p.name for p in out.iterdir()) == ["dataset.json"] + [f"shard-{i:05d}.parquet" for i in range(10)]
    assert json.loads((out / "dataset.json").read_text())["settings"]["seed"] == 7
    print(f"synth: {summary['samples_per_core_second']:.0f} samples a core-second, {summary['seconds']:.1f} s, peak {summary['peak_rss_mb_per_worker']:.0f} MB a worker")

    table = synth.read(out)
    assert table.num_rows == 20_000
    np.testing.assert_array_equal(column(table, "sample"), np.arange(20_000))  # complete, each once
    widths = {"angles": 23, "joints": 75, "keypoints_3d": 63, "keypoints_camera": 63, "keypoints_2d": 42, "visible": 21, "intrinsics": 9, "extrinsics": 16}
    for name, width in widths.items():
        assert table.schema.field(name).type.list_size == width, name
    assert table.schema.field("ball_centre").type.list_size == 3
    assert table.schema.field("mask").type == table.schema.field("object_mask").type == pa.binary(64 * 64 // 8)  # a bit a pixel
    assert table.schema.field("depth").type == pa.binary(64 * 64 * 2)  # float16
    assert set(table.column_names) == set(widths) | {"sample", "shard", "side", "hand_length", "hand_breadth", "gesture_from", "gesture_to", "blend", "ball_radius", "ball_centre", "mask", "object_mask", "depth"}
    for name in widths:
        if name != "visible":
            assert np.isfinite(column(table, name, widths[name]).astype(np.float64)).all(), name
    assert set(column(table, "side")) == {"right", "left"}
    lengths = column(table, "hand_length")
    assert synth.LENGTH_M[0] <= lengths.min() and lengths.max() <= synth.LENGTH_M[1]
    assert len(np.unique(lengths)) == 10  # a hand a shard
    assert set(column(table, "gesture_from")) == {"rest", "hold_ball", *dqhand.Hand.builtin(vertices=1000).gesture_poses()}
    held = column(table, "ball_radius") > 0
    assert 0.23 < held.mean() < 0.27
    assert (column(table, "gesture_from")[held] == "hold_ball").all()

    # The same as one process makes it, whatever the workers: the first and last shards.
    settings = synth.Settings(samples=20_000, seed=7, image_size=64, shard_size=2_000, ball_share=0.25)
    for shard in (0, 9):
        alone = one_process_shard(settings, shard)
        assert alone.equals(table.slice(shard * 2_000, alone.num_rows).select(alone.column_names)), shard

    # Every keypoint in the image lies on the hand or its ball (a joint is inside the hand, so
    # it projects into its silhouette), give or take a pixel for the fingertips on its outline.
    hands, balls, depth = synth.images(table)
    assert np.isfinite(depth).all() and ((depth > 0) == (hands | balls)).all() and not (hands & balls).any()
    assert balls[held].any(axis=(1, 2)).mean() > 0.6 and not balls[~held].any()
    masks = hands | balls
    pixels = np.rint(column(table, "keypoints_2d", 42).reshape(-1, 21, 2)).astype(int)
    inside = ((pixels >= 0) & (pixels < 64)).all(axis=-1)
    assert inside.mean() > 0.99
    grown = masks.copy()
    for dy, dx in [(-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (-1, 1), (1, -1), (1, 1)]:
        grown |= np.roll(masks, (dy, dx), axis=(1, 2))
    rows = np.arange(table.num_rows)[:, None]
    on = grown[rows, pixels[..., 1].clip(0, 63), pixels[..., 0].clip(0, 63)]
    assert on[inside].all()
    visible = column(table, "visible", 21)
    assert 0.3 < visible.mean() < 0.95
    # A visible keypoint shows the hand, never the ball in front of it.
    assert not (visible & balls[rows, pixels[..., 1].clip(0, 63), pixels[..., 0].clip(0, 63)]).any()
    # A visible keypoint's pixel shows the skin over it: joint centres lie a few millimetres
    # under the skin (a finger is 15-20 mm thick), so the depth map there is a little nearer.
    camera = column(table, "keypoints_camera", 63).reshape(-1, 21, 3)
    surface = depth[rows, pixels[..., 1].clip(0, 63), pixels[..., 0].clip(0, 63)]
    under = np.median((camera[..., 2] - surface)[visible])
    assert 0.002 < under < 0.012, under

    # The rows' hands and angles give the rows' keypoints, on a hand rebuilt from its columns.
    row = table.slice(4_321, 1)
    hand = dqhand.Hand.builtin(length=float(column(row, "hand_length")[0]), breadth=float(column(row, "hand_breadth")[0]), side=column(row, "side")[0], vertices=settings.vertices)
    keypoints = hand.keypoints(column(row, "angles", 23).astype(np.float64))
    np.testing.assert_allclose(keypoints.reshape(1, -1), column(row, "keypoints_3d", 63), atol=1e-5)


def test_close_on_ball_says_whether_the_open_hand_was_clear():
    hand = dqhand.Hand.builtin(vertices=1000)
    fist = hand.gesture_poses()["fist"].astype(np.float64)
    # A ball in the palm, and one a metre away.
    angles, clear = hand.close_on_ball(np.stack([fist, fist]), [[0, 0, -0.04], [0, -1.0, 0]], [0.03, 0.03])
    assert clear.dtype == np.bool_ and clear.tolist() == [False, True]
    np.testing.assert_allclose(angles[1], fist, atol=1e-6)  # nothing in the way: the fist
    with pytest.raises(ValueError, match=r"^radii\[0\]: 0.5 m is not a ball's radius \(0.005 to 0.2 m\)$"):
        hand.close_on_ball(fist[None], [[0, 0, 0]], [0.5])
    with pytest.raises(ValueError, match=r"^centres: expected an array of shape \(1, 3\)"):
        hand.close_on_ball(fist[None], [0, 0, 0], [0.03])


def test_held_balls_are_wrapped_without_sinking_in(tmp_path):
    summary = synth.synth(240, tmp_path / "set", seed=5, image_size=64, shard_size=120, ball_share=1.0, meshes=True, use_ray=False)
    table = synth.read(tmp_path / "set")
    radius, centre = column(table, "ball_radius"), column(table, "ball_centre", 3)
    assert summary["samples"] == 240 and (radius > 0).all()
    skin = synth.meshes(table)
    # The skin against the analytic ball (no rasterizer involved), per sample: never inside.
    distance = np.linalg.norm(skin - centre[:, None], axis=2) - radius[:, None]
    gap = distance.min(axis=1)
    assert gap.min() > 0
    # Every finger closed on it: each finger's flexion against the fist's it closed towards
    # (an open hand, 0, fails this).
    hand = dqhand.Hand.builtin(length=float(column(table, "hand_length")[0]), breadth=float(column(table, "hand_breadth")[0]), side=column(table, "side")[0], vertices=synth.Settings(1).vertices)
    fist = hand.gesture_poses()["fist"]
    angles = column(table, "angles", 23)
    shares = {}
    for finger in ("thumb", "index", "middle", "ring", "pinky"):
        flex = [i for i, n in enumerate(hand.dof_names) if n.startswith(finger) and n.endswith(".flex")]
        shares[finger] = angles[:, flex].sum(axis=1) / fist[flex].sum()
        assert np.mean(shares[finger] > 0.25) > 0.9, finger
    # Wrapped: more skin near the ball (within 10 mm) than the open hand has there.
    open_skin = hand.skin(np.zeros((1, 23)))[0]
    near_open = (np.linalg.norm(open_skin[None] - centre[:120, None], axis=2) - radius[:120, None] < 0.01).sum(axis=1)
    near = (distance[:120] < 0.01).sum(axis=1)
    assert np.median(near) > 2 * np.median(near_open)
    # The grasp tracked (the fist itself) would sink in: what the contact-constrained hand
    # prevents.
    sunk = (np.linalg.norm(hand.skin(np.repeat(fist[None], 120, axis=0)) - centre[:120, None], axis=2) - radius[:120, None]).min(axis=1)
    assert np.median(sunk) < -0.005
    print(
        f"held balls: skin gap median {np.median(gap) * 1e3:.1f} mm (least {gap.min() * 1e3:.2f}, within 3 mm in {np.mean(gap < 0.003):.0%}); "
        f"closure of the fist's, median: {', '.join(f'{k} {np.median(v):.2f}' for k, v in shares.items())}; "
        f"skin vertices within 10 mm, median {np.median(near):.0f} (open hand {np.median(near_open):.0f}); the fist unconstrained sinks in by {-np.median(sunk) * 1e3:.0f} mm"
    )
    # The ball is in sight unless the hand hides it (the camera behind the hand).
    _, balls, _ = synth.images(table)
    assert balls.any(axis=(1, 2)).mean() > 0.6


def ray_worker_running(task):
    """The pid of a Ray worker whose title says it runs `task` (`ray::Map(task)`, or
    `ray::ReadRange->Map(task)` where Ray Data fuses the read into the map), if one does."""
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                title = (entry / "cmdline").read_bytes().split(b"\0")[0].decode()
            except OSError:
                continue
            if title.startswith("ray::") and f"Map({task})" in title:
                return int(entry.name)
    return None


def test_a_killed_worker_shard_is_made_again(local_ray, tmp_path):
    out = tmp_path / "set"
    killed = []

    def kill_one():
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            pid = ray_worker_running("shard_task")
            if pid is not None:
                time.sleep(1.0)  # mid-shard: past the hand's build, into the samples
                if ray_worker_running("shard_task") == pid:
                    os.kill(pid, signal.SIGKILL)
                    killed.append(pid)
                    return
            time.sleep(0.05)

    killer = threading.Thread(target=kill_one)
    killer.start()
    summary = synth.synth(3_000, out, seed=11, image_size=64, shard_size=500, vertices=1000)
    killer.join()
    assert len(killed) == 1, "no worker was running a shard to kill"
    assert not Path(f"/proc/{killed[0]}").exists()
    assert summary["shards"] == 6
    assert sorted(p.name for p in out.iterdir()) == ["dataset.json"] + [f"shard-{i:05d}.parquet" for i in range(6)]
    table = synth.read(out)
    np.testing.assert_array_equal(column(table, "sample"), np.arange(3_000))
    np.testing.assert_array_equal(np.bincount(column(table, "shard")), [500] * 6)
    # The shard made again is the one it would have been: every shard as one process makes it.
    settings = synth.Settings(samples=3_000, seed=11, image_size=64, shard_size=500, vertices=1000)
    for shard in range(6):
        alone = one_process_shard(settings, shard)
        assert alone.equals(table.slice(shard * 500, 500).select(alone.column_names)), shard


def test_a_shard_is_written_whole_or_not_at_all(tmp_path):
    # A worker killed after the shard's first row group: no shard file, only its partial one.
    code = f"""
import os
import pyarrow.parquet as pq
from pathlib import Path
from dqhand import synth
write = pq.ParquetWriter.write_table
def write_then_die(self, table, *args, **kwargs):
    write(self, table, *args, **kwargs)
    os._exit(9)
pq.ParquetWriter.write_table = write_then_die
synth.write_shard(synth.Settings(samples=300, image_size=16, vertices=1000), Path({str(tmp_path)!r}), 0)
"""
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 9, run.stderr
    names = [p.name for p in tmp_path.iterdir()]
    assert not any(n.startswith("shard-") for n in names), names
    assert len([n for n in names if n.startswith(".shard-00000.parquet.") and n.endswith(".partial")]) == 1, names
    # Written to the end, the same call leaves the shard and nothing else.
    synth.write_shard(synth.Settings(samples=300, image_size=16, vertices=1000), tmp_path, 0)
    assert (tmp_path / "shard-00000.parquet").is_file()


def test_bad_arguments(tmp_path):
    with pytest.raises(synth.SynthError, match=r"^samples: 0 is not a whole number from 1 to"):
        synth.synth(0, tmp_path / "a", use_ray=False)
    with pytest.raises(synth.SynthError, match=r"^image_size: 8 is not a whole number from 16 to 4096$"):
        synth.synth(10, tmp_path / "a", image_size=8, use_ray=False)
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "x").write_text("")
    with pytest.raises(synth.SynthError, match=r"full: not empty"):
        synth.synth(10, tmp_path / "full", use_ray=False)
    with pytest.raises(synth.SynthError, match=r"no shard-\*\.parquet files"):
        synth.read(tmp_path / "full")
    run = subprocess.run([sys.executable, "-m", "dqhand.synth", "--samples", "-3", "--out", str(tmp_path / "b")], capture_output=True, text=True)
    assert run.returncode == 2
    assert run.stderr == "dqhand.synth: samples: -3 is not a whole number from 1 to 10000000000\n"
    assert not (tmp_path / "b").exists()

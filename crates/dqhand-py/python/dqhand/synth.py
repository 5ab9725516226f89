"""Synthetic hand data sets on Ray Data: ``python -m dqhand.synth --samples N --out DIR``.

Each sample is a plausible random hand (side and size per shard), posed within its joint
limits around and between the gesture library's shapes, skinned (DQB), seen by a random
pinhole camera; a row holds its angles, 3D joints and keypoints, the camera, 2D keypoints with
visibility, and a hand mask and depth map rendered in software (``dqhand.render_depth``).

The job is one Ray Data ``map`` over shard numbers: each task makes its shard from its own seed
(``(seed, shard)``) and writes ``shard-NNNNN.parquet`` whole or not at all (a temporary file,
then a rename), so the data set is the same whatever the number of workers, and a shard whose
worker dies is made again by Ray's retry, never lost or written twice.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import sys
import time
import uuid
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Dict, Iterator, List, Optional, Union

import numpy as np

from . import Hand, MEDIAPIPE_KEYPOINTS, render_depth

FORMAT = "dqhand-synth/1"
# Each Ray task has one core: rayon (the skinning and rasterizer threads) keeps to it.
ONE_THREAD = {"env_vars": {"RAYON_NUM_THREADS": "1"}}
# Adult hand lengths (wrist crease to middle fingertip, m) and breadth / length ratios, roughly
# the 5th to 95th percentiles of women and men together (ANSUR II).
LENGTH_M = (0.165, 0.210)
BREADTH_RATIO = (0.42, 0.48)
# How far a pose strays from its gesture blend: a normal spread per angle (radians).
POSE_NOISE_RAD = math.radians(8.0)
# The camera's horizontal field of view (degrees) and the share of the image's half-width the
# hand's bounding sphere spans.
FOV_DEG = (45.0, 75.0)
FILL = (0.45, 0.9)
# A keypoint (a joint centre, inside the finger) counts as visible where the surface drawn at its
# pixel is at most this far in front of it: about a finger's thickness, less than two fingers'.
VISIBLE_DEPTH_M = 0.02
# Samples rendered at a time within a shard (a Parquet row group), fewer for large images: bounds
# a worker's memory (a 256 px chunk peaks near 200 MB).
CHUNK = 100
CHUNK_PIXELS = 6_500_000
# A held ball's radius (m): a golf ball to a large orange.
BALL_RADIUS_M = (0.02, 0.045)
# How a held ball is placed: from the palm's centre, this far towards the fingers (m), in a
# direction spread by this much (a normal spread of the unit palm normal), just clear of the
# open hand by this gap (m); the hand then closes on it from open.
BALL_ALONG_M = (-0.01, 0.03)
BALL_TILT = 0.15
BALL_GAP_M = (0.002, 0.006)
# A ball still touching the open hand's collision proxies is moved out this far, up to this
# many times.
BALL_STEP_M = 0.003
BALL_RETRIES = 8
# The grasp the hand closes towards on a ball: the fist, each angle spread by this (radians).
GRASP_NOISE_RAD = math.radians(5.0)


class SynthError(ValueError):
    """A bad argument or output folder, with a one-line message naming it."""


@dataclass(frozen=True)
class Settings:
    """What a data set is made from; with the seed, it decides every byte of every shard."""

    samples: int
    seed: int = 0
    image_size: int = 256
    shard_size: int = 2000
    vertices: int = 4000
    meshes: bool = False
    ball_share: float = 0.0

    def check(self) -> None:
        for name, low, high in (("samples", 1, 10**10), ("image_size", 16, 4096), ("shard_size", 1, 10**6), ("vertices", 1000, 60_000)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
                raise SynthError(f"{name}: {value!r} is not a whole number from {low} to {high}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise SynthError(f"seed: {self.seed!r} is not a whole number ≥ 0")
        if isinstance(self.ball_share, bool) or not isinstance(self.ball_share, (int, float)) or not 0 <= self.ball_share <= 1:
            raise SynthError(f"ball_share: {self.ball_share!r} is not a share from 0 to 1")

    @property
    def shards(self) -> int:
        return math.ceil(self.samples / self.shard_size)

    def shard_samples(self, shard: int) -> range:
        """The sample numbers of shard `shard`."""
        return range(shard * self.shard_size, min((shard + 1) * self.shard_size, self.samples))


def shard_path(out: Path, shard: int) -> Path:
    return out / f"shard-{shard:05d}.parquet"


def _look_at(rng: np.random.Generator, centre: np.ndarray, distance: np.ndarray) -> np.ndarray:
    """World-to-camera transforms (B, 4, 4), OpenCV axes (x right, y down, z forward): each
    camera `distance` from `centre` in a uniformly random direction, looking at it, rolled at
    random."""
    count = len(centre)
    back = rng.normal(size=(count, 3))
    back /= np.linalg.norm(back, axis=1, keepdims=True)
    forward = -back
    roll = rng.normal(size=(count, 3))
    down = roll - np.sum(roll * forward, axis=1, keepdims=True) * forward
    down /= np.linalg.norm(down, axis=1, keepdims=True)
    right = np.cross(down, forward)
    rotation = np.stack([right, down, forward], axis=1)  # rows: the camera's axes in the world
    position = centre + back * distance[:, None]
    pose = np.tile(np.eye(4), (count, 1, 1))
    pose[:, :3, :3] = rotation
    pose[:, :3, 3] = -np.einsum("bij,bj->bi", rotation, position)
    return pose


def _poses(rng: np.random.Generator, templates: np.ndarray, names: List[str], limits: np.ndarray, count: int):
    """`count` poses: half held on a gesture, half between two, each angle spread by
    POSE_NOISE_RAD and kept within its limits."""
    start = rng.integers(len(templates), size=count)
    end = rng.integers(len(templates), size=count)
    blend = np.where(rng.random(count) < 0.5, 0.0, rng.random(count))
    angles = templates[start] * (1 - blend[:, None]) + templates[end] * blend[:, None]
    angles += rng.normal(scale=POSE_NOISE_RAD, size=angles.shape)
    angles = np.clip(angles, limits[:, 0], limits[:, 1])
    end = np.where(blend == 0.0, start, end)
    return angles, [names[i] for i in start], [names[i] for i in end], blend


def icosphere(subdivisions: int = 2):
    """A unit sphere's vertices (V, 3) and triangles (F, 3): an icosahedron whose triangles are
    split in four `subdivisions` times, its vertices pushed onto the sphere."""
    t = (1 + 5**0.5) / 2
    vertices = [np.array(v, dtype=np.float64) for v in [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        middles: Dict[tuple, int] = {}

        def middle(a: int, b: int) -> int:
            key = (min(a, b), max(a, b))
            if key not in middles:
                middles[key] = len(vertices)
                vertices.append((vertices[a] + vertices[b]) / 2)
            return middles[key]

        split = []
        for a, b, c in faces:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            split += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = split
    points = np.array(vertices)
    return points / np.linalg.norm(points, axis=1, keepdims=True), np.array(faces, dtype=np.int64)


def _palm(hand: Hand, fist: np.ndarray):
    """The open hand's palm centre, its axis towards the fingers and its normal (the side the
    fingers close to), world, from the rest joints and the fist's fingertips."""
    names = MEDIAPIPE_KEYPOINTS
    rest = hand.keypoints(np.zeros((1, len(hand.dof_names))))[0].astype(np.float64)
    knuckles = rest[[names.index(n) for n in ("INDEX_FINGER_MCP", "MIDDLE_FINGER_MCP", "RING_FINGER_MCP", "PINKY_MCP")]].mean(axis=0)
    centre = (rest[0] + knuckles) / 2
    axis = (knuckles - rest[0]) / np.linalg.norm(knuckles - rest[0])
    tips = hand.keypoints(fist[None])[0][[names.index(n) for n in ("INDEX_FINGER_TIP", "MIDDLE_FINGER_TIP", "RING_FINGER_TIP", "PINKY_TIP")]].mean(axis=0)
    normal = tips - centre
    normal -= normal.dot(axis) * axis
    return centre, axis, normal / np.linalg.norm(normal)


def _ball_centres(rng: np.random.Generator, open_skin: np.ndarray, palm, radii: np.ndarray):
    """Centres of balls of `radii` in front of the palm, each clear of the open hand's skin
    (moved out along its direction past every skin vertex nearer than its radius and gap),
    and those directions."""
    centre, axis, normal = palm
    count = len(radii)
    start = centre + rng.uniform(*BALL_ALONG_M, size=count)[:, None] * axis
    direction = normal + rng.normal(scale=BALL_TILT, size=(count, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    reach = radii + rng.uniform(*BALL_GAP_M, size=count)
    # Along the ray start + t·direction, vertex v is nearer than `reach` for t within
    # w·d ± sqrt((w·d)² − |w|² + reach²), w = v − start: the ball goes past the last of those.
    w = open_skin[None] - start[:, None]
    along = np.einsum("bvk,bk->bv", w, direction)
    room = along**2 - np.sum(w * w, axis=2) + reach[:, None] ** 2
    out = np.where(room > 0, along + np.sqrt(np.maximum(room, 0)), 0).max(axis=1)
    return start + np.maximum(out, 0)[:, None] * direction, direction


def make_shard(settings: Settings, shard: int) -> Iterator[Dict[str, np.ndarray]]:
    """The samples of shard `shard`, CHUNK at a time as columns: a pure function of
    `settings` and `shard` (its random numbers come from the seed sequence (seed, shard))."""
    rng = np.random.default_rng([settings.seed, shard])
    side = ["right", "left"][rng.integers(2)]
    length = rng.uniform(*LENGTH_M)
    breadth = length * rng.uniform(*BREADTH_RATIO)
    hand = Hand.builtin(length=length, breadth=breadth, side=side, vertices=settings.vertices)
    gestures = hand.gesture_poses()
    names = ["rest", *gestures]
    templates = np.stack([np.zeros(len(hand.dof_names)), *gestures.values()])
    limits = hand.limits.astype(np.float64)
    faces = hand.faces.astype(np.int64)
    fist = gestures["fist"].astype(np.float64)
    palm = _palm(hand, fist)
    open_skin = hand.skin(np.zeros((1, len(hand.dof_names))))[0].astype(np.float64)
    sphere, sphere_faces = icosphere()
    size = settings.image_size
    numbers = settings.shard_samples(shard)
    # The balls' own random stream: a data set without balls is the same whatever ball_share's
    # draws would have been.
    ball_rng = np.random.default_rng([settings.seed, shard, 1])
    chunk = max(1, min(CHUNK, CHUNK_PIXELS // size**2))
    for first in range(numbers.start, numbers.stop, chunk):
        count = min(chunk, numbers.stop - first)
        angles, start, end, blend = _poses(rng, templates, names, limits, count)
        # Some hands hold a ball instead: closed from open towards a fist until each finger
        # touches it (the contact-constrained hand), so nothing sinks into it.
        holds = ball_rng.random(count) < settings.ball_share
        ball_radius = np.where(holds, ball_rng.uniform(*BALL_RADIUS_M, size=count), 0.0)
        ball_centre = np.zeros((count, 3))
        if holds.any():
            held = np.flatnonzero(holds)
            grasp = np.clip(fist + ball_rng.normal(scale=GRASP_NOISE_RAD, size=(len(held), len(fist))), limits[:, 0], limits[:, 1])
            centres, away = _ball_centres(ball_rng, open_skin, palm, ball_radius[held])
            closed, clear = hand.close_on_ball(grasp, centres, ball_radius[held])
            # A ball the open hand's proxies touch (they stand off the skin, most at the thumb)
            # would keep that finger open: moved out until the open hand is clear.
            for _ in range(BALL_RETRIES):
                if clear.all():
                    break
                redo = ~clear
                centres[redo] += BALL_STEP_M * away[redo]
                closed[redo], clear[redo] = hand.close_on_ball(grasp[redo], centres[redo], ball_radius[held][redo])
            ball_centre[held], angles[held] = centres, closed
            for i in held:
                start[i] = end[i] = "hold_ball"
            blend[held] = 0.0
        vertices = hand.skin(angles)
        joints = hand.joints(angles)
        keypoints = hand.keypoints(angles)

        low = np.minimum(vertices.min(axis=1), np.where(holds[:, None], ball_centre - ball_radius[:, None], np.inf))
        high = np.maximum(vertices.max(axis=1), np.where(holds[:, None], ball_centre + ball_radius[:, None], -np.inf))
        centre = (low + high) / 2
        radius = np.linalg.norm(vertices - centre[:, None], axis=2).max(axis=1)
        radius = np.where(holds, np.maximum(radius, np.linalg.norm(ball_centre - centre, axis=1) + ball_radius), radius)
        fov = np.radians(rng.uniform(*FOV_DEG, size=count))
        focal = (size / 2) / np.tan(fov / 2)
        distance = radius / np.sin(rng.uniform(*FILL, size=count) * fov / 2)
        # Aim near the hand, not always at its centre.
        aim = centre + rng.uniform(-0.25, 0.25, size=(count, 3)) * radius[:, None]
        extrinsics = _look_at(rng, aim, distance)
        intrinsics = np.zeros((count, 3, 3))
        intrinsics[:, 0, 0] = intrinsics[:, 1, 1] = focal
        intrinsics[:, :2, 2] = (size - 1) / 2 + rng.normal(scale=0.02 * size, size=(count, 2))
        intrinsics[:, 2, 2] = 1

        depth = render_depth(vertices, faces, intrinsics, extrinsics, size, size)
        hand_mask = depth > 0
        if holds.any():
            # The hand with its ball: the hand's mask is where the hand is the nearest surface.
            scene = np.concatenate([vertices[held], ball_centre[held, None] + ball_radius[held, None, None] * sphere[None]], axis=1)
            both = render_depth(scene, np.concatenate([faces, sphere_faces + vertices.shape[1]]), intrinsics[held], extrinsics[held], size, size)
            hand_mask[held] &= depth[held] <= both
            depth[held] = both
        object_mask = (depth > 0) & ~hand_mask
        camera = np.einsum("bij,bkj->bki", extrinsics[:, :3, :3], keypoints) + extrinsics[:, None, :3, 3]
        pixels = np.einsum("bij,bkj->bki", intrinsics, camera)
        pixels = pixels[..., :2] / pixels[..., 2:]
        column, row = np.rint(pixels[..., 0]).astype(int), np.rint(pixels[..., 1]).astype(int)
        inside = (column >= 0) & (column < size) & (row >= 0) & (row < size)
        at = (np.arange(count)[:, None], row.clip(0, size - 1), column.clip(0, size - 1))
        visible = inside & hand_mask[at] & (camera[..., 2] - depth[at] <= VISIBLE_DEPTH_M)

        columns = {
            "sample": np.arange(first, first + count, dtype=np.int64),
            "shard": np.full(count, shard, dtype=np.int32),
            "side": np.array([side] * count),
            "hand_length": np.full(count, length, dtype=np.float32),
            "hand_breadth": np.full(count, breadth, dtype=np.float32),
            "gesture_from": np.array(start),
            "gesture_to": np.array(end),
            "blend": blend.astype(np.float32),
            "angles": angles.astype(np.float32),
            "joints": joints.reshape(count, -1),
            "keypoints_3d": keypoints.reshape(count, -1),
            "keypoints_camera": camera.astype(np.float32).reshape(count, -1),
            "keypoints_2d": pixels.astype(np.float32).reshape(count, -1),
            "visible": visible,
            "intrinsics": intrinsics.astype(np.float32).reshape(count, 9),
            "extrinsics": extrinsics.astype(np.float32).reshape(count, 16),
            "ball_radius": ball_radius.astype(np.float32),
            "ball_centre": ball_centre.astype(np.float32),
            "mask": np.packbits(hand_mask, axis=-1).reshape(count, -1),
            "object_mask": np.packbits(object_mask, axis=-1).reshape(count, -1),
            "depth": depth.astype("<f2").reshape(count, -1).view(np.uint8),
        }
        if settings.meshes:
            columns["vertices"] = vertices.astype("<f4").reshape(count, -1).view(np.uint8)
        yield columns


# Columns stored as one fixed-size binary value a sample (little-endian bytes): Parquet writes a
# list column with levels for each of its values, which for images costs more than the rest.
BYTES = {"mask", "object_mask", "depth", "vertices"}


def _table(columns: Dict[str, np.ndarray]):
    """The columns as an Arrow table: per-sample arrays as fixed-size lists, images bytes."""
    import pyarrow as pa

    arrays = {}
    for name, values in columns.items():
        if name in BYTES:
            arrays[name] = pa.array([row.tobytes() for row in values], type=pa.binary(values.shape[1]))
        elif values.ndim == 1:
            arrays[name] = pa.array(values)
        else:
            arrays[name] = pa.FixedSizeListArray.from_arrays(pa.array(values.reshape(-1)), values.shape[1])
    return pa.table(arrays)


def write_shard(settings: Settings, out: Path, shard: int) -> Dict[str, float]:
    """Makes shard `shard` and writes it whole, or not at all, to `shard_path(out, shard)`;
    returns what it took (samples, seconds, bytes, the process's peak memory)."""
    import pyarrow.parquet as pq

    began = time.perf_counter()
    final = shard_path(out, shard)
    partial = out / f".{final.name}.{uuid.uuid4().hex}.partial"
    metadata = {b"dqhand.format": FORMAT.encode(), b"dqhand.settings": json.dumps(asdict(settings)).encode()}
    writer = None
    try:
        for chunk in make_shard(settings, shard):
            table = _table(chunk)
            if writer is None:
                writer = pq.ParquetWriter(partial, table.schema.with_metadata(metadata), compression="zstd", use_dictionary=["side", "gesture_from", "gesture_to"])
            writer.write_table(table)
        writer.close()
        writer = None
        # On disk before it is renamed: a machine that stops keeps the whole shard or none.
        with open(partial, "rb") as written:
            os.fsync(written.fileno())
        os.replace(partial, final)
    finally:
        if writer is not None:
            writer.close()
        partial.unlink(missing_ok=True)
    return {
        "shard": shard,
        "samples": len(settings.shard_samples(shard)),
        "seconds": time.perf_counter() - began,
        "bytes": final.stat().st_size,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    }


def shard_task(row: Dict[str, int], settings: Settings, out: Path) -> Dict[str, float]:
    """The Ray Data map over shard numbers (a worker running it is titled
    `ray::Map(shard_task)`)."""
    return write_shard(settings, out, int(row["id"]))


def _prepare(out: Union[str, os.PathLike], settings: Settings) -> Path:
    settings.check()
    # Absolute: Ray's workers do not share the driver's working folder.
    out = Path(out).resolve()
    if out.exists() and not out.is_dir():
        raise SynthError(f"{out}: not a folder")
    if out.is_dir() and any(out.iterdir()):
        raise SynthError(f"{out}: not empty (a data set is written into a new or empty folder)")
    out.mkdir(parents=True, exist_ok=True)
    return out


def _on_ray(settings: Settings, out: Path, address: Optional[str], num_cpus: Optional[int]) -> List[Dict[str, float]]:
    import ray

    started = not ray.is_initialized()
    if started:
        # One rayon thread a task: Ray gives each task a core, and rayon would take them all.
        ray.init(address=address, num_cpus=num_cpus if address is None else None, include_dashboard=False, runtime_env=ONE_THREAD, logging_level="warning")
    try:
        shards = ray.data.range(settings.shards, override_num_blocks=settings.shards)
        done = shards.map(shard_task, fn_kwargs={"settings": settings, "out": out}, num_cpus=1, runtime_env=ONE_THREAD)
        return done.take_all()
    finally:
        if started:
            ray.shutdown()


def synth(
    samples: int,
    out: Union[str, os.PathLike],
    *,
    seed: int = 0,
    image_size: int = 256,
    shard_size: int = 2000,
    vertices: int = 4000,
    meshes: bool = False,
    ball_share: float = 0.0,
    address: Optional[str] = None,
    num_cpus: Optional[int] = None,
    use_ray: bool = True,
) -> Dict[str, object]:
    """Makes a data set of `samples` samples in the new or empty folder `out` (Parquet shards
    of `shard_size` samples and `dataset.json`): on Ray Data (a local Ray on `num_cpus` cores,
    all by default, or the cluster at `address`; an already started Ray is used as it is), or
    with `use_ray=False` in this process, shard after shard. Returns what `dataset.json`
    holds: the settings, the counts, the time and the samples a second a core."""
    settings = Settings(samples=samples, seed=seed, image_size=image_size, shard_size=shard_size, vertices=vertices, meshes=meshes, ball_share=ball_share)
    out = _prepare(out, settings)
    began = time.perf_counter()
    if use_ray:
        done = _on_ray(settings, out, address, num_cpus)
    else:
        done = []
        for shard in range(settings.shards):
            done.append(write_shard(settings, out, shard))
            print(f"dqhand.synth: shard {shard + 1}/{settings.shards}", file=sys.stderr)
    seconds = time.perf_counter() - began
    # A try killed while it wrote left its partial file behind; the retry wrote the shard.
    for partial in out.glob(".shard-*.partial"):
        partial.unlink()
    # A retried shard was reported by each try that finished: one report a shard.
    reports = {int(r["shard"]): r for r in done}
    missing = [s for s in range(settings.shards) if not shard_path(out, s).is_file()]
    if missing or sorted(reports) != list(range(settings.shards)):
        raise RuntimeError(f"{out}: shards {missing or sorted(set(range(settings.shards)) - set(reports))} were not written")
    busy = sum(float(r["seconds"]) for r in reports.values())
    summary = {
        "format": FORMAT,
        "settings": asdict(settings),
        "keypoints": MEDIAPIPE_KEYPOINTS,
        "shards": settings.shards,
        "samples": samples,
        "bytes": sum(int(r["bytes"]) for r in reports.values()),
        "seconds": seconds,
        "samples_per_core_second": samples / busy,
        "peak_rss_mb_per_worker": max(float(r["peak_rss_mb"]) for r in reports.values()),
    }
    (out / "dataset.json").write_text(json.dumps(summary, indent=1) + "\n")
    return summary


def read(out: Union[str, os.PathLike]):
    """The data set in `out` as one Arrow table, ordered by sample."""
    import pyarrow.parquet as pq

    shards = sorted(Path(out).glob("shard-*.parquet"))
    if not shards:
        raise SynthError(f"{out}: no shard-*.parquet files (not a dqhand.synth data set)")
    return pq.read_table(shards).sort_by("sample")


def _bytes_of(column, dtype) -> np.ndarray:
    """A fixed-size binary column's values, one row each, as `dtype` (rows, values)."""
    values = column.combine_chunks()
    width = values.type.byte_width
    data = np.frombuffer(values.buffers()[1], dtype=np.uint8)[values.offset * width : (values.offset + len(values)) * width]
    return data.view(dtype).reshape(len(values), -1)


def images(table) -> tuple:
    """The hand masks (N, S, S) bool, the held objects' masks (N, S, S) bool and the depth maps
    (N, S, S) float32 (m, 0 where there is nothing) of a table's rows."""
    size = json.loads(table.schema.metadata[b"dqhand.settings"])["image_size"]

    def unpack(name):
        return np.unpackbits(_bytes_of(table[name], np.uint8).reshape(-1, size, (size + 7) // 8), axis=-1, count=size).astype(bool)

    depth = _bytes_of(table["depth"], "<f2").reshape(-1, size, size).astype(np.float32)
    return unpack("mask"), unpack("object_mask"), depth


def meshes(table) -> np.ndarray:
    """The skinned vertices (N, V, 3), m, of a table's rows (a data set made with `meshes`)."""
    return _bytes_of(table["vertices"], "<f4").reshape(table.num_rows, -1, 3)


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m dqhand.synth", description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, required=True, help="how many samples")
    parser.add_argument("--out", required=True, help="a new or empty folder for the shards")
    parser.add_argument("--seed", type=int, default=0, help="the data set's seed (default 0)")
    parser.add_argument("--image-size", type=int, default=256, help="mask and depth side in pixels (default 256)")
    parser.add_argument("--shard-size", type=int, default=2000, help="samples a shard, a Ray task (default 2000)")
    parser.add_argument("--vertices", type=int, default=4000, help="the hand mesh's vertices (default 4000)")
    parser.add_argument("--meshes", action="store_true", help="also store each sample's skinned vertices")
    parser.add_argument("--ball-share", type=float, default=0.0, help="the share of samples whose hand holds a ball (default 0)")
    parser.add_argument("--address", help="an existing Ray cluster (ray.init's address); by default a local Ray")
    parser.add_argument("--num-cpus", type=int, help="the local Ray's cores (default all)")
    parser.add_argument("--no-ray", action="store_true", help="make the shards in this process, one after another")
    args = parser.parse_args(argv)
    try:
        summary = synth(
            args.samples, args.out, seed=args.seed, image_size=args.image_size, shard_size=args.shard_size, vertices=args.vertices,
            meshes=args.meshes, ball_share=args.ball_share, address=args.address, num_cpus=args.num_cpus, use_ray=not args.no_ray,
        )
    except (SynthError, OSError) as error:
        print(f"dqhand.synth: {error}", file=sys.stderr)
        return 2
    except Exception as error:  # a failed Ray task or cluster: its first line, not a traceback
        print(f"dqhand.synth: {type(error).__name__}: {str(error).strip().splitlines()[0] if str(error).strip() else 'failed'}", file=sys.stderr)
        return 1
    print(
        f"dqhand.synth: {summary['samples']} samples in {summary['shards']} shards, {summary['bytes'] / 1e6:.1f} MB, {summary['seconds']:.1f} s; "
        f"{summary['samples_per_core_second']:.0f} samples a core-second, peak memory a worker {summary['peak_rss_mb_per_worker']:.0f} MB"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())

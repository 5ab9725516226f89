"""``python -m dqhand.bench``: poses a second through the Python API, beside the Rust batch
(``dqhand skin --poses``), the Rust kernel alone (``dqhand bench``) and a NumPy LB, measured in
one run on the same random poses of the built-in hand.

The Rust rows need the ``dqhand`` binary (``--dqhand``, else ``$DQHAND_BIN``, else ``dqhand`` on
the PATH); without one they are left out and the output says so.
"""

import argparse
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from . import Hand

# The NumPy LB blends each pose with einsum, far slower: timed on at most this many poses.
NUMPY_POSES = 50


def timed(run, repeats):
    """Median and slowest seconds of ``repeats`` calls of ``run``."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return statistics.median(times), max(times)


def numpy_lb(rest, joints, weights, transforms):
    """LB of every pose in plain NumPy: per vertex, the weighted sum of its joints' matrices applied to it."""
    homogeneous = np.concatenate([rest, np.ones((len(rest), 1), rest.dtype)], 1)
    out = np.empty((len(transforms), len(rest), 3), np.float32)
    for b, t in enumerate(transforms):
        blended = np.einsum("vk,vkij->vij", weights, t[joints])
        out[b] = np.einsum("vij,vj->vi", blended, homogeneous)[:, :3]
    return out


def cpu_name():
    try:
        with open("/proc/cpuinfo") as info:
            for line in info:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m dqhand.bench", description=__doc__.splitlines()[0].strip("`: "))
    parser.add_argument("--poses", type=int, default=1000, help="poses per batch (default 1000)")
    parser.add_argument("--repeats", type=int, default=5, help="batches timed per row; the median is reported (default 5)")
    parser.add_argument("--dqhand", default=os.environ.get("DQHAND_BIN") or shutil.which("dqhand"), help="the dqhand binary for the Rust rows")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of a table")
    args = parser.parse_args(argv)
    if args.poses < 1 or args.repeats < 1:
        parser.error("--poses and --repeats must be at least 1")
    if args.dqhand and not os.access(args.dqhand, os.X_OK):
        parser.error(f"--dqhand {args.dqhand}: not an executable file")

    hand = Hand.builtin()
    low, high = hand.limits[:, 0], hand.limits[:, 1]
    angles = np.random.default_rng(0).uniform(low, high, size=(args.poses, len(low)))
    rows = []

    def row(what, seconds, poses):
        median, slowest = seconds
        rows.append({"what": what, "us_per_pose": 1e6 * median / poses, "us_per_pose_slowest": 1e6 * slowest / poses, "poses": poses})

    row("Python API, DQB (hand.skin)", timed(lambda: hand.skin(angles), args.repeats), args.poses)
    row("Python API, DQB with normals", timed(lambda: hand.skin(angles, normals=True), args.repeats), args.poses)
    row("Python API, LB", timed(lambda: hand.skin(angles, method="lb"), args.repeats), args.poses)
    few = angles[:NUMPY_POSES]
    joints, weights = hand.influences
    transforms = hand.skinning_transforms(few)
    row(f"NumPy LB (einsum; skinning_transforms given), {len(few)} poses", timed(lambda: numpy_lb(hand.rest_vertices, joints, weights, transforms), args.repeats), len(few))

    skipped = None
    if args.dqhand:
        with tempfile.TemporaryDirectory() as work:
            lines = [json.dumps({"model": "full", "angles_deg": dict(zip(hand.dof_names, np.degrees(a).tolist()))}) for a in angles]
            poses_file = os.path.join(work, "poses.jsonl")
            with open(poses_file, "w") as f:
                f.write("\n".join(lines) + "\n")
            out = os.path.join(work, "out")
            command = [args.dqhand, "skin", "--poses", poses_file, "--format", "ply", "--out", out]
            row("dqhand skin --poses (Rust batch: reads the poses, writes a PLY each)", timed(lambda: subprocess.run(command, check=True, capture_output=True), args.repeats), args.poses)
            report = json.loads(subprocess.run([args.dqhand, "bench", "--frames", "300", "--json"], check=True, capture_output=True, text=True).stdout)
            threads = {}
            for variant in report["variants"]:
                # The run-time choice's rows (no forced lookup strategy).
                if variant["method"] == "dqb" and not variant["normals"] and variant["kernel"] == report["kernel"] and variant.get("strategy") is None:
                    threads[variant["threads"]] = variant
            for variant in threads.values():
                what = f"dqhand bench: DQB kernel alone, {report['kernel']}, {variant['threads']} thread(s) on one frame"
                rows.append({"what": what, "us_per_pose": variant["us_per_frame"], "us_per_pose_slowest": variant["p90_us"], "poses": report["frames"]})
    else:
        skipped = "no dqhand binary (--dqhand, $DQHAND_BIN or PATH): the Rust rows are left out"

    api = rows[0]["us_per_pose"]
    batch = next((r["us_per_pose"] for r in rows if r["what"].startswith("dqhand skin")), None)
    kernel = min((r["us_per_pose"] for r in rows if r["what"].startswith("dqhand bench")), default=None)
    result = {
        "machine": f"{cpu_name()}, {os.cpu_count()} cores; Python {platform.python_version()}, NumPy {np.__version__}",
        "hand": f"{len(hand.rest_vertices)} vertices, {len(hand.dof_names)} angles",
        "rows": rows,
        "python_over_rust_batch": api / batch if batch else None,
        "python_over_rust_kernel": api / kernel if kernel else None,
        "skipped": skipped,
    }
    if args.json:
        print(json.dumps(result))
        return 0
    print(f"{result['machine']}\nthe built-in hand: {result['hand']}; {args.poses} random poses within the joint ranges, median of {args.repeats}\n")
    print(f"{'what':<86} {'µs a pose':>10} {'slowest':>9} {'poses/s':>9} {'÷ API':>6}")
    for r in rows:
        print(f"{r['what']:<86} {r['us_per_pose']:>10.1f} {r['us_per_pose_slowest']:>9.1f} {1e6 / r['us_per_pose']:>9.0f} {r['us_per_pose'] / api:>6.2f}")
    if batch and kernel:
        verdict = "meets" if api <= 1.1 * batch else "misses"
        print(f"\nthe Python API takes {api / batch:.2f} times the Rust batch's time a pose ({verdict} the target of 1.1; the batch writes a file a pose,")
        print(f"so this says little) and {api / kernel:.2f} times the Rust kernel's alone on every core (no files, one frame split over the threads)")
    if skipped:
        print(f"\n{skipped}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

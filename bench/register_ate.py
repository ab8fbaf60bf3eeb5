#!/usr/bin/python3
"""ATE of `mlmap register` on the stress benchmark's simulated sequences, with drifting odometry.

For each scene directory written by bench/icp_stress.py (scan_NNN.xyz, poses_true.txt), the
odometry is the true trajectory with a random error added to every increment: translation up
to --max-t m (mostly horizontal), yaw up to --max-yaw deg, roll/pitch up to 1 deg (seeded).
Runs each given mlmap binary's `register --reference` and prints its ATE lines side by side.

Usage: bench/register_ate.py WORK_DIR [--mlmap BIN ...] [--max-t 0.3] [--max-yaw 10] [--seed 5]
"""
import argparse, math, os, re, subprocess, sys
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from icp_stress import quaternion, read_tum, rot  # noqa: E402


def drifted(true, rng, max_t, max_yaw):
    odom = [true[0]]
    for a, b in zip(true, true[1:]):
        step = np.linalg.inv(a) @ b
        d = rng.normal(size=3) * np.array([1, 1, 0.2])
        E = np.eye(4)
        E[:3, :3] = rot((0, 0, 1), math.radians(rng.uniform(-max_yaw, max_yaw))) @ rot(
            (1, 0, 0), math.radians(rng.uniform(-1, 1)))
        E[:3, 3] = d / np.linalg.norm(d) * rng.uniform(0, max_t)
        odom.append(odom[-1] @ step @ E)
    return odom


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("work")
    ap.add_argument("--mlmap", action="append", default=[])
    ap.add_argument("--max-t", type=float, default=0.3)
    ap.add_argument("--max-yaw", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=5)
    a = ap.parse_args()
    print(f"odometry: every increment off by up to {a.max_t} m and {a.max_yaw} deg yaw (seed {a.seed})")
    print("| scene | scans | method | odometry ATE cm / deg | scan-to-map ATE cm / deg | refined ATE cm / deg |")
    print("|---|---|---|---|---|---|")
    for name in sorted(os.listdir(a.work)):
        scene = os.path.join(a.work, name)
        if not os.path.exists(os.path.join(scene, "poses_true.txt")):
            continue
        true = read_tum(os.path.join(scene, "poses_true.txt"))
        rng = np.random.default_rng(a.seed + sum(map(ord, name)))
        odom = drifted(true, rng, a.max_t, a.max_yaw)
        odom_path = os.path.join(scene, f"odom_drift_{a.seed}.txt")
        with open(odom_path, "w") as f:
            for k, T in enumerate(odom):
                x, y, z, w = quaternion(T[:3, :3])
                f.write(f"{k} {T[0, 3]!r} {T[1, 3]!r} {T[2, 3]!r} {x!r} {y!r} {z!r} {w!r}\n")
        scans = [os.path.join(scene, f"scan_{k:03d}.xyz") for k in range(len(true))]
        for binary in a.mlmap:
            p = subprocess.run([binary, "--quiet", "register", "--poses", odom_path, "--reference",
                                os.path.join(scene, "poses_true.txt"), "-o", os.path.join(scene, "registered.txt")]
                               + scans, capture_output=True, text=True)
            ate = {}
            for line in p.stdout.splitlines():
                m = re.match(r"(\S+)\s*ATE: translation RMS ([\d.]+) cm .*rotation RMS ([\d.]+) deg", line)
                if m:
                    ate[m.group(1)] = f"{m.group(2)} / {m.group(3)}"
            if p.returncode != 0:
                ate = {"odometry": "failed: " + p.stderr.strip()[-80:]}
            print(f"| {name} | {len(true)} | {binary} | {ate.get('odometry', '')} | {ate.get('scan-to-map', '')} | "
                  f"{ate.get('refined', '')} |")


if __name__ == "__main__":
    main()

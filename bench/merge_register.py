#!/usr/bin/python3
"""`mlmap merge --register` from the identity on generated cases: two halves of a room mapped apart.

For each scene of bench/icp_stress.py's split (simulated into WORK if not there yet), the
scans' first half is mapped in the world frame and the second half in a frame F moved by up
to --max-t m horizontally and turned up to --max-yaw deg about the vertical (random, seeded
by the split), each by `mlmap build --no-octree` from the true poses. `mlmap merge --register`
(no --initial: the start is the identity) must find F. A case is placed when the transform it
applies is within 2 cm and 0.2 deg of F; refused when merge declines (exit status 1); wrong
when it merges more than that off. Prints per scene: placed / refused / wrong, median and worst
error of the merged ones, median and worst time of the merge command, and the load.

Tuning uses --split tune (room seeds 1-3); the default report split (room seeds 11-13) is held out.

Usage: bench/merge_register.py [--build build] [--split report|tune] [--cases 4] [--work DIR]
                               [--scenes lab,symmetric,rooms] [--max-t 1.0] [--max-yaw 30]
"""
import argparse, math, os, subprocess, sys, tempfile, time
import json
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from icp_stress import quaternion, read_tum, rot, scenes_for  # noqa: E402

PLACED_CM, PLACED_DEG = 2.0, 0.2


def write_tum(path, poses):
    with open(path, "w") as f:
        for k, T in enumerate(poses):
            x, y, z, w = quaternion(T[:3, :3])
            f.write(f"{k} {T[0, 3]!r} {T[1, 3]!r} {T[2, 3]!r} {x!r} {y!r} {z!r} {w!r}\n")


def read_matrix(path):
    rows = [line for line in open(path) if not line.startswith("#")]
    return np.array([float(v) for line in rows for v in line.split()]).reshape(4, 4)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "build"))
    ap.add_argument("--split", choices=["report", "tune"], default="report")
    ap.add_argument("--scenes", default="lab,symmetric,rooms")
    ap.add_argument("--cases", type=int, default=4, help="random frames per scene")
    ap.add_argument("--max-t", type=float, default=1.0)
    ap.add_argument("--max-yaw", type=float, default=30.0)
    ap.add_argument("--work", default="")
    a = ap.parse_args()
    mlmap = os.path.join(a.build, "mlmap")
    work = a.work or tempfile.mkdtemp(prefix="merge_register_")
    os.makedirs(work, exist_ok=True)
    loads = [os.getloadavg()[0]]
    rows = []
    for name, scene in scenes_for(a.split, a.scenes.split(",")):
        scene_dir = os.path.join(work, name)
        if not os.path.exists(os.path.join(scene_dir, "poses_true.txt")):
            json.dump(scene, open(scene_dir + ".json", "w"), indent=1)
            subprocess.run([mlmap, "--quiet", "simulate", scene_dir + ".json", "-o", scene_dir], check=True,
                           capture_output=True)
        true = read_tum(os.path.join(scene_dir, "poses_true.txt"))
        scans = [os.path.join(scene_dir, f"scan_{k:03d}.xyz") for k in range(len(true))]
        half = len(true) // 2
        base = os.path.join(scene_dir, "half_a.mlmap")
        write_tum(os.path.join(scene_dir, "half_a.txt"), true[:half])
        subprocess.run([mlmap, "--quiet", "build", "--no-octree", "--poses", os.path.join(scene_dir, "half_a.txt"),
                        "-o", base] + scans[:half], check=True, capture_output=True)
        rng = np.random.default_rng(sum(map(ord, name)) + (0 if a.split == "tune" else 7919))
        for case in range(a.cases):
            angle = rng.uniform(0, 2 * math.pi)
            F = np.eye(4)
            F[:3, :3] = rot((0, 0, 1), math.radians(rng.uniform(-a.max_yaw, a.max_yaw)))
            F[:3, 3] = np.array([math.cos(angle), math.sin(angle), 0.0]) * rng.uniform(0, a.max_t)
            poses_b = os.path.join(scene_dir, f"half_b_{case}.txt")
            write_tum(poses_b, [np.linalg.inv(F) @ T for T in true[half:]])
            other = os.path.join(scene_dir, f"half_b_{case}.mlmap")
            subprocess.run([mlmap, "--quiet", "build", "--no-octree", "--poses", poses_b, "-o", other] + scans[half:],
                           check=True, capture_output=True)
            found = os.path.join(scene_dir, f"found_{case}.txt")
            if os.path.exists(found):
                os.remove(found)
            loads.append(os.getloadavg()[0])
            started = time.time()
            p = subprocess.run([mlmap, "--quiet", "merge", base, other, "--register", "--write-transform", found,
                                "-o", os.path.join(scene_dir, "merged.mlmap")], capture_output=True, text=True)
            seconds = time.time() - started
            yaw_true = math.degrees(math.atan2(F[1, 0], F[0, 0]))
            if p.returncode != 0:
                rows.append((name, yaw_true, np.linalg.norm(F[:3, 3]), None, None, seconds, p.stderr.strip()[-120:]))
                continue
            E = np.linalg.inv(F) @ read_matrix(found)
            t_cm = 100 * float(np.linalg.norm(E[:3, 3]))
            r_deg = math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(E[:3, :3]) - 1) / 2))))
            rows.append((name, yaw_true, np.linalg.norm(F[:3, 3]), t_cm, r_deg, seconds, ""))
        print(f"  {name}: {a.cases} cases done", file=sys.stderr)
    print(f"split {a.split}; frames up to {a.max_t} m and {a.max_yaw} deg apart, start the identity; "
          f"load average (1 min) {min(loads):.1f}-{max(loads):.1f} on {os.cpu_count()} CPUs")
    print(f"placed: within {PLACED_CM:g} cm and {PLACED_DEG:g} deg; wrong: merged further off; refused: merge declined")
    print()
    print("| scene | cases | placed | refused | wrong | t err cm median / max | rot err deg median / max | "
          "s per merge median / max |")
    print("|---|---|---|---|---|---|---|---|")
    for scene in [n for n, _ in scenes_for(a.split, a.scenes.split(","))] + ["all"]:
        sel = [r for r in rows if r[0] == scene or scene == "all"]
        merged = [r for r in sel if r[3] is not None]
        placed = sum(1 for r in merged if r[3] < PLACED_CM and r[4] < PLACED_DEG)
        err = (f"{np.median([r[3] for r in merged]):.2f} / {max(r[3] for r in merged):.2f} | "
               f"{np.median([r[4] for r in merged]):.3f} / {max(r[4] for r in merged):.3f}") if merged else "- | -"
        times = [r[5] for r in sel]
        print(f"| {scene} | {len(sel)} | {placed} | {len(sel) - len(merged)} | {len(merged) - placed} | {err} | "
              f"{np.median(times):.1f} / {max(times):.1f} |")
    print()
    for r in rows:
        status = "refused: " + r[6] if r[3] is None else f"{r[3]:.2f} cm {r[4]:.3f} deg"
        print(f"  {r[0]}: frame {r[2]:.2f} m, yaw {r[1]:+.1f} deg -> {status} ({r[5]:.1f} s)")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""ATE of `mlmap register` on the stress benchmark's simulated sequences, with drifting odometry.

For each scene directory of bench/icp_stress.py's splits (scan_NNN.xyz, poses_true.txt), the
odometry is the true trajectory with a random error added to every increment: translation up
to --max-t m (mostly horizontal), yaw up to --max-yaw deg, roll/pitch up to 1 deg (seeded).
Runs each given mlmap binary's `register --reference` and prints its ATE lines side by side,
then per binary how many sequences end within 1 cm and 0.1 deg (the refined ATE; issue 20's
target) and which do not.

With --split (tune, report, fresh or all), the scenes are simulated into WORK/SPLIT (kept for the
next run) and every sequence runs for each --seed and --max-yaw given. The suite the README
quotes: --split all --seed 5 6 7 8 --max-yaw 30 10 (192 sequences; ~15 min per binary on 2
cores). Without --split, WORK holds scene directories already (as icp_stress.py --work leaves).

Usage: bench/register_ate.py [WORK] [--split tune|report|fresh|all] [--mlmap BIN ...]
                             [--seed 5 ...] [--max-yaw 10 ...] [--max-t 0.3]
"""
import argparse, math, os, re, subprocess, sys
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from icp_stress import ROOT, quaternion, read_tum, rot, simulated_split  # noqa: E402


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


def run_sequence(scene, name, seed, max_t, max_yaw, binaries):
    """Writes the drifted odometry, runs each binary; {binary: (odometry, scan-to-map, refined) or error}."""
    true = read_tum(os.path.join(scene, "poses_true.txt"))
    rng = np.random.default_rng(seed + sum(map(ord, name)))
    odom = drifted(true, rng, max_t, max_yaw)
    odom_path = os.path.join(scene, f"odom_drift_{seed}.txt")
    with open(odom_path, "w") as f:
        for k, T in enumerate(odom):
            x, y, z, w = quaternion(T[:3, :3])
            f.write(f"{k} {T[0, 3]!r} {T[1, 3]!r} {T[2, 3]!r} {x!r} {y!r} {z!r} {w!r}\n")
    scans = [os.path.join(scene, f"scan_{k:03d}.xyz") for k in range(len(true))]
    out = {}
    for binary in binaries:
        p = subprocess.run([binary, "--quiet", "register", "--poses", odom_path, "--reference",
                            os.path.join(scene, "poses_true.txt"), "-o", os.path.join(scene, "registered.txt")]
                           + scans, capture_output=True, text=True)
        ate = {}
        for line in p.stdout.splitlines():
            m = re.match(r"(\S+)\s*ATE: translation RMS ([\d.]+) cm .*rotation RMS ([\d.]+) deg", line)
            if m:
                ate[m.group(1)] = (float(m.group(2)), float(m.group(3)))
        out[binary] = ate if p.returncode == 0 else "failed: " + p.stderr.strip()[-80:]
    return len(true), out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("work", nargs="?", default="")
    ap.add_argument("--split", choices=["tune", "report", "fresh", "all"])
    ap.add_argument("--mlmap", action="append", default=[])
    ap.add_argument("--max-t", type=float, default=0.3)
    ap.add_argument("--max-yaw", type=float, nargs="+", default=[10.0])
    ap.add_argument("--seed", type=int, nargs="+", default=[5])
    a = ap.parse_args()
    binaries = a.mlmap or [os.path.join(ROOT, "build", "mlmap")]
    if a.split:
        base = a.work or os.path.join(ROOT, "out", "register_ate")
        splits = ["tune", "report", "fresh"] if a.split == "all" else [a.split]
        which = "lab,corridor,symmetric,long-corridor,rooms".split(",")
        groups = [(split, simulated_split(split, which, os.path.join(base, split), binaries[0], dict(os.environ)))
                  for split in splits]
    else:
        if not a.work:
            ap.error("give WORK (scene directories) or --split")
        scenes = [(n, os.path.join(a.work, n)) for n in sorted(os.listdir(a.work))
                  if os.path.exists(os.path.join(a.work, n, "poses_true.txt"))]
        groups = [(os.path.basename(os.path.normpath(a.work)), scenes)]
    fmt = lambda v: f"{v[0]:.2f} / {v[1]:.3f}" if v else ""
    within = {}  # (group, binary) -> [ok, count, failures]
    print("| split | scene | scans | seed | max yaw | method | odometry ATE cm / deg | scan-to-map ATE cm / deg | "
          "refined ATE cm / deg |")
    print("|---|---|---|---|---|---|---|---|---|")
    for group, scenes in groups:
        for max_yaw in a.max_yaw:
            for seed in a.seed:
                for name, scene in scenes:
                    count, results = run_sequence(scene, name, seed, a.max_t, max_yaw, binaries)
                    for binary, ate in results.items():
                        tally = within.setdefault((group, binary), [0, 0, []])
                        tally[1] += 1
                        if isinstance(ate, str):
                            print(f"| {group} | {name} | {count} | {seed} | {max_yaw:g} | {binary} | {ate} | | |")
                            tally[2].append(f"{name} (seed {seed}, {max_yaw:g} deg): failed")
                            continue
                        refined = ate.get("refined")
                        print(f"| {group} | {name} | {count} | {seed} | {max_yaw:g} | {binary} | "
                              f"{fmt(ate.get('odometry'))} | {fmt(ate.get('scan-to-map'))} | {fmt(refined)} |",
                              flush=True)
                        if refined and refined[0] <= 1.0 and refined[1] <= 0.1:
                            tally[0] += 1
                        else:
                            tally[2].append(f"{name} (seed {seed}, {max_yaw:g} deg): {fmt(refined)}")
    print("\nwithin 1 cm and 0.1 deg (refined ATE):")
    for binary in binaries:
        ok = sum(v[0] for (g, b), v in within.items() if b == binary)
        count = sum(v[1] for (g, b), v in within.items() if b == binary)
        parts = ", ".join(f"{g} {v[0]}/{v[1]}" for (g, b), v in within.items() if b == binary)
        print(f"- {binary}: {ok} of {count} ({parts})")
        for (g, b), v in within.items():
            if b == binary and v[2]:
                print(f"  {g}, not within: " + "; ".join(v[2]))


if __name__ == "__main__":
    main()

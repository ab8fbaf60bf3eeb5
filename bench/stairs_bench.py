#!/usr/bin/env python3
"""Stairs seen from their foot and from above: a generated stairwell, scored step by step.

    /usr/bin/python3 bench/stairs_bench.py [--build build] [--against OTHER_BUILD] [--out out/stairs]
        [--heights 0.3,1.2] [--yaws 4,30] [--cells 0.05,0.1] [--noises 0.01] [--known-noise]
        [--peers /work/build-peers]

OctoMap's fr079 scan sees a flight of 13 steps from near floor level, where each step is a band of
scan lines on its riser and nosing and a plane at the flight's slope passes within a few
centimetres of all of them; the project's own scenes see their stairs from a robot's 1.2 m. This
generates a stairwell (14 x 4.5 x 5 m, a flight of 13 steps of 0.14 m on 0.30 m treads, 3 m wide,
turned `yaw` degrees to the grid) scanned by the simulated tilting laser (0.25 deg beams, 0.5 deg
tilt steps, 1 cm range noise or each of --noises) from two poses 2 and 4 m before the first riser
at each tilt-axis height, builds it at each cell size (true poses, --no-octree; build assumes its
default 3 cm of noise unless --known-noise gives it the simulated one), detects planes and labels
every point (`mlmap label`). With --peers, CGAL's efficient RANSAC runs on the same points, told
the simulated noise (epsilon 3 sigma). Per variant: the treads and risers with >= 30 points, how many lie >= 70 %
on one patch that holds no other step's >= 10 % ("found"), and the patches tilted 15-75 deg that
hold points of two treads or more ("ramps": a plane through the flight). Made in session 37 after
the step cut (src/planes/stepped.hpp) was written, and not tuned on.
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def scene(height, yaw, noise=0.01):
    return {
        "_comment": "bench/stairs_bench.py: a stairwell seen from the foot of its flight",
        "name": "stairwell",
        "scan_pattern": {"field_of_view_deg": 270, "angular_step_deg": 0.25, "tilt_start_deg": -30,
                         "tilt_end_deg": 40, "tilt_step_deg": 0.5, "min_range": 0.023, "max_range": 30,
                         "range_sigma": noise, "mount_height": height, "seed": 3},
        "odometry": {"translation_noise_per_m": 0.0, "yaw_noise_per_rad": 0.0, "yaw_noise_per_m": 0.0, "seed": 7},
        "poses": [{"x": 3.0, "y": 2.0, "yaw_deg": yaw}, {"x": 1.0, "y": 2.3, "yaw_deg": 0}],
        "surfaces": [
            {"type": "rectangle", "name": "floor", "class": "floor", "min": [0, 0, 0], "max": [14, 4.5, 0]},
            {"type": "rectangle", "name": "ceiling", "class": "ceiling", "min": [0, 0, 5.0], "max": [14, 4.5, 5.0]},
            {"type": "rectangle", "name": "wall_west", "class": "wall", "min": [0, 0, 0], "max": [0, 4.5, 5.0], "facing": "+x"},
            {"type": "rectangle", "name": "wall_east", "class": "wall", "min": [14, 0, 0], "max": [14, 4.5, 5.0], "facing": "-x"},
            {"type": "rectangle", "name": "wall_south", "class": "wall", "min": [0, 0, 0], "max": [14, 0, 5.0], "facing": "+y"},
            {"type": "rectangle", "name": "wall_north", "class": "wall", "min": [0, 4.5, 0], "max": [14, 4.5, 5.0], "facing": "-y"},
            {"type": "stairs", "name": "flight", "start": [5.0, 0.6], "yaw_deg": yaw, "width": 3.0, "steps": 13,
             "riser": 0.14, "tread": 0.30, "top_depth": 1.5},
        ],
    }


def run(cmd):
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"stairs_bench: {' '.join(cmd)} failed:\n{done.stderr}")


def truth_of(sim):
    """Per point its true surface id (the scans' order), and the names of the ids."""
    scans = sorted(os.path.join(sim, f) for f in os.listdir(sim) if f.startswith("scan_"))
    truth = np.concatenate([np.loadtxt(f, usecols=3) for f in scans]).astype(int)
    names = {p["id"]: p["name"] for p in json.load(open(os.path.join(sim, "planes_true.json")))["planes"]}
    return scans, truth, names


def judge(truth, names, labels, normals):
    """(steps seen, steps found, ramps) for one method's point labels: `labels` per point, a plane id
    where it is a key of `normals` (plane id -> unit normal), anything else for none."""
    step_ids = [t for t, n in names.items() if n.startswith("flight.tread") or n.startswith("flight.riser")]
    sizes = {t: int((truth == t).sum()) for t in step_ids}
    steps = [t for t in step_ids if sizes[t] >= 30]
    found = []
    for t in steps:
        ids, counts = np.unique(labels[truth == t], return_counts=True)
        best = max(((c, i) for i, c in zip(ids, counts) if i in normals), default=(0, None))
        if best[0] < 0.7 * sizes[t]:
            continue
        on = truth[labels == best[1]]
        if any(o != t and o in sizes and (on == o).sum() >= 0.1 * sizes[o] for o in set(on.tolist())):
            continue
        found.append(names[t].split(".")[1])
    ramps = 0
    for plane_id, normal in normals.items():
        tilt = np.degrees(np.arccos(min(1.0, abs(normal[2]))))
        if 15.0 < tilt < 75.0:
            treads = {o for o in set(truth[labels == plane_id].tolist()) if names.get(o, "").startswith("flight.tread")}
            ramps += len(treads) >= 2
    return len(steps), found, ramps


def score(mlmap, sim, labelled, cell, tag, range_sigma=None):
    scans, truth, names = labelled
    poses = os.path.join(sim, "poses_true.txt")
    noise = ["--range-sigma", f"{range_sigma:g}"] if range_sigma else []
    run([mlmap, "-q", "build", *scans, "--poses", poses, "--no-octree", "--cell-size", str(cell), "-o", tag + ".mlmap"] +
        noise)
    run([mlmap, "-q", "planes", tag + ".mlmap", "-o", tag + ".planes.mlmap", "--json", tag + ".planes.json",
         "--threads", "2"])
    run([mlmap, "-q", "label", tag + ".planes.mlmap", *scans, "--poses", poses, "-o", tag + ".labels.xyz"])
    labels = np.loadtxt(tag + ".labels.xyz", usecols=3).astype(int)
    # `mlmap label` writes -1 for a point on no plane; ids are the planes JSON's.
    normals = {p["id"]: p["normal"] for p in json.load(open(tag + ".planes.json"))["planes"] if p["id"] > 0}
    return judge(truth, names, labels, normals)


def score_cgal(peers, sim, labelled, noise, tag):
    """CGAL's efficient RANSAC on the same world points, told the simulated noise (ε = 3σ, as
    bench/peer_scene.py), at most 60 planes of at least 200 points."""
    _, truth, names = labelled
    world = os.path.join(sim, "all_world.xyz")  # the scans' points in their order, world frame
    done = subprocess.run([os.path.join(peers, "cgal_ransac"), world, "--eps", f"{3 * noise:g}", "--angle", "20",
                           "--min-support", "200", "--max-planes", "60", "--labels", tag + ".cgal.labels"],
                          capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"stairs_bench: cgal_ransac failed:\n{done.stderr}")
    planes = json.loads(done.stdout)["planes"]
    labels = np.loadtxt(tag + ".cgal.labels", dtype=int)
    if len(labels) != len(truth):
        sys.exit(f"stairs_bench: cgal_ransac labelled {len(labels)} points of {len(truth)}")
    return judge(truth, names, labels, {k: p["normal"] for k, p in enumerate(planes)})


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--against", help="another build directory, run side by side")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "stairs"))
    ap.add_argument("--heights", default="0.3,1.2", help="tilt-axis heights above the floor, m")
    ap.add_argument("--yaws", default="4,30", help="the flight's turn to the grid, deg")
    ap.add_argument("--cells", default="0.05,0.1")
    ap.add_argument("--peers", help="build directory of ../shared/peers: CGAL's efficient RANSAC side by side")
    ap.add_argument("--known-noise", action="store_true",
                    help="give build the simulated noise (--range-sigma), as CGAL is given it; default: build's 3 cm")
    ap.add_argument("--noises", default="0.01",
                    help="the simulated range noise, m")
    a = ap.parse_args()
    builds = [a.build] + ([a.against] if a.against else [])
    for b in builds:
        if not os.access(os.path.join(b, "mlmap"), os.X_OK):
            sys.exit(f"stairs_bench: no mlmap in {b} (build it first: bash scripts/build.sh)")
    if a.peers and not os.access(os.path.join(a.peers, "cgal_ransac"), os.X_OK):
        sys.exit(f"stairs_bench: no cgal_ransac in {a.peers} (build ../shared/peers, or leave out --peers)")
    os.makedirs(a.out, exist_ok=True)
    print("| build | range noise m | sensor height m | flight turned deg | cell m | steps found (of treads and risers seen) | ramps | not found |")
    print("|---|---|---|---|---|---|---|---|")
    totals = {b: [0, 0, 0] for b in builds + (["CGAL"] if a.peers else [])}
    for noise in [float(n) for n in a.noises.split(",")]:
        for height in [float(h) for h in a.heights.split(",")]:
            for yaw in [float(y) for y in a.yaws.split(",")]:
                # The folder of the default noise keeps its old name (runs compare across sessions).
                folder = os.path.join(a.out, f"h{height}-yaw{yaw}" + ("" if noise == 0.01 else f"-noise{noise:g}"))
                os.makedirs(folder, exist_ok=True)
                scene_file = os.path.join(folder, "stairwell.json")
                with open(scene_file, "w") as f:
                    json.dump(scene(height, yaw, noise), f, indent=1)
                sim = os.path.join(folder, "sim")
                run([os.path.join(a.build, "mlmap"), "-q", "simulate", scene_file, "-o", sim])
                labelled = truth_of(sim)  # read once: every build, cell size and CGAL score the same points
                for b in builds:
                    for cell in [float(c) for c in a.cells.split(",")]:
                        tag = os.path.join(folder, f"{os.path.basename(os.path.normpath(os.path.dirname(b + '/')))}-{cell}")
                        seen, found, ramps = score(os.path.join(b, "mlmap"), sim, labelled, cell, tag,
                                                   noise if a.known_noise else None)
                        totals[b][0] += len(found)
                        totals[b][1] += seen
                        totals[b][2] += ramps
                        print(f"| {b} | {noise:g} | {height} | {yaw:g} | {cell} | {len(found)} of {seen} | {ramps} | "
                              f"{seen - len(found)} |", flush=True)
                if a.peers:
                    seen, found, ramps = score_cgal(a.peers, sim, labelled, noise, os.path.join(folder, "cgal"))
                    totals["CGAL"][0] += len(found)
                    totals["CGAL"][1] += seen
                    totals["CGAL"][2] += ramps
                    print(f"| CGAL (points, ε {3 * noise:g} m) | {noise:g} | {height} | {yaw:g} | - | {len(found)} of {seen} | "
                          f"{ramps} | {seen - len(found)} |", flush=True)
    for b, (found, seen, ramps) in totals.items():
        print(f"| {b} | all | | | | {found} of {seen} | {ramps} | |")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Registration stress benchmark: pairwise ICP from random starts on scenes nothing was tuned on.

Scenes (each simulated with `mlmap simulate` at a coarse scan pattern, 0.5 deg beams and
1 deg lines, so a run takes minutes):
  lab, corridor      the shipped maps/lab.json and maps/corridor.json (their poses)
  symmetric          an empty 7 x 7 x 3 m square room: nothing breaks its symmetry
  long-corridor      a 30 m x 2.2 m corridor with a few doors and niches
  room-S             rooms generated from seed S: random size, 3-8 pieces of furniture
                     (tables, cabinets, shelves, turned at random), 5-15 pieces of clutter
                     (crates, bins, posts), 4 poses on a random walk
Range noise 1, 2 or 3 cm (by seed). For each scene, up to --pairs consecutive scan pairs;
for each pair --starts random starts of each size:
  small   translation up to 0.5 m, yaw up to 10 deg, roll/pitch up to 2 deg
  large   translation up to 0.5 m, yaw 10-30 deg, roll/pitch up to 2 deg
(the start = true relative pose composed with the random error, turned about the sensor).
Each start runs mlmap (`mlmap_bench icp-starts`: alignVerified, `mlmap register`'s
preprocessing; --plain adds the single ICP run it replaced) and the peers Open3D and PCL
(point-to-plane, their defaults: 0.05 m voxels, gates 0.5 then 0.1 m) from the same start.

Tuning split: the constants of alignVerified were tuned (by hand) on `--split tune` (room
seeds 1-3, noise seed 1); the default `--split report` uses room seeds 11-13 and noise seed
2 (other noise and other starts on the shipped scenes too), which no tuning saw. `--split fresh`
(rooms 21-26 at all three noise levels, noise seed 3) was generated in session 35, after both
had been looked at many times: report on it, never tune on it.

Prints per scene and start size: success rate (final error < 2 cm and < 0.5 deg), median and
worst translation / rotation error, median time per pair (preparation + ICP, reading
excluded), per method, and the verification figures of mlmap (verified share, false
"verified", retries).

Usage:
  bench/icp_stress.py [--build build] [--peers-build /work/build-peers] [--split report|tune|fresh]
                      [--pairs 3] [--starts 3] [--threads 2] [--work DIR] [--skip-peers]
                      [--plain] [--scenes lab,corridor,symmetric,long-corridor,rooms]
"""
import argparse, json, math, os, subprocess, sys, tempfile, time
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PATTERN = {"field_of_view_deg": 270, "angular_step_deg": 0.5, "tilt_start_deg": -46, "tilt_end_deg": 46,
           "tilt_step_deg": 1.0, "min_range": 0.023, "max_range": 30, "mount_height": 1.2}
SUCCESS_CM, SUCCESS_DEG = 2.0, 0.5


def rect(lo, hi, cls, facing=None):
    r = {"type": "rectangle", "class": cls, "min": lo, "max": hi}
    if facing:
        r["facing"] = facing
    return r


def room_walls(w, d, h):
    return [rect([0, 0, 0], [w, d, 0], "floor"), rect([0, 0, h], [w, d, h], "ceiling"),
            rect([0, 0, 0], [0, d, h], "wall", "+x"), rect([w, 0, 0], [w, d, h], "wall", "-x"),
            rect([0, 0, 0], [w, 0, h], "wall", "+y"), rect([0, d, 0], [w, d, h], "wall", "-y")]


def in_cabinet(surfaces, x, y, sensor_z=1.2):
    """Whether a sensor at (x, y) would stand inside a box that reaches above it (a cabinet or shelf:
    its scan sees the box's inside only, and no registration can place it). Rooms 22, 24 and 26 had
    such poses; the tuning and report rooms (1-3, 11-13) have none, and stay as they were."""
    for s in surfaces:
        if s["type"] == "box" and "center" in s:
            (cx, cy, cz), (sx, sy, sz) = s["center"], s["size"]
            a = math.radians(s.get("yaw_deg", 0.0))
            dx, dy = x - cx, y - cy
            u, v = dx * math.cos(a) + dy * math.sin(a), -dx * math.sin(a) + dy * math.cos(a)
            if abs(u) <= sx / 2 and abs(v) <= sy / 2 and cz + sz / 2 > sensor_z:
                return True
    return False


def random_room(seed):
    """A room with furniture and clutter, 4 poses on a random walk through its free middle."""
    rng = np.random.default_rng(1000 + seed)
    w, d, h = rng.uniform(5, 12), rng.uniform(4, 10), rng.uniform(2.6, 3.5)
    surfaces = room_walls(w, d, h)
    for _ in range(rng.integers(3, 9)):  # furniture: tables, cabinets, shelves
        kind = rng.choice(["table", "cabinet", "shelf"])
        if kind == "table":
            size = [rng.uniform(0.8, 2.0), rng.uniform(0.6, 1.0), 0.04]
            z = rng.uniform(0.7, 0.78)
        elif kind == "cabinet":
            size = [rng.uniform(0.5, 2.0), rng.uniform(0.4, 0.6), rng.uniform(1.0, 2.2)]
            z = size[2] / 2
        else:
            size = [rng.uniform(0.8, 1.8), rng.uniform(0.3, 0.45), rng.uniform(1.5, 2.4)]
            z = size[2] / 2
        c = [rng.uniform(0.6, w - 0.6), rng.uniform(0.6, d - 0.6), z]
        surfaces.append({"type": "box", "class": "table" if kind == "table" else "other", "center": c,
                         "size": size, "yaw_deg": float(rng.uniform(-90, 90))})
    for _ in range(rng.integers(5, 16)):  # clutter: crates, bins, posts
        if rng.random() < 0.6:
            s = rng.uniform(0.2, 0.6)
            surfaces.append({"type": "box", "class": "other", "size": [s, rng.uniform(0.2, 0.6), rng.uniform(0.2, 0.9)],
                             "center": [rng.uniform(0.4, w - 0.4), rng.uniform(0.4, d - 0.4), 0.45],
                             "yaw_deg": float(rng.uniform(-90, 90))})
            surfaces[-1]["center"][2] = surfaces[-1]["size"][2] / 2
        else:
            surfaces.append({"type": "cylinder", "center": [rng.uniform(0.4, w - 0.4), rng.uniform(0.4, d - 0.4)],
                             "radius": float(rng.uniform(0.05, 0.3)), "z": [0, float(rng.uniform(0.4, h))]})
    poses, x, y, yaw = [], rng.uniform(1.2, w - 1.2), rng.uniform(1.2, d - 1.2), rng.uniform(-180, 180)
    for _ in range(200):  # the first pose outside the cabinets
        if not in_cabinet(surfaces, x, y):
            break
        x, y = rng.uniform(1.2, w - 1.2), rng.uniform(1.2, d - 1.2)
    for _ in range(4):
        poses.append({"x": float(x), "y": float(y), "yaw_deg": float(yaw)})
        for _ in range(50):  # the next pose 0.8-2 m away, inside the room
            step, turn = rng.uniform(0.8, 2.0), rng.uniform(-60, 60)
            nx, ny = x + step * math.cos(math.radians(yaw + turn)), y + step * math.sin(math.radians(yaw + turn))
            if 1.0 < nx < w - 1.0 and 1.0 < ny < d - 1.0 and not in_cabinet(surfaces, nx, ny):
                x, y, yaw = nx, ny, yaw + turn
                break
        else:
            yaw += 90
    return {"name": f"room-{seed}", "poses": poses, "surfaces": surfaces}


def symmetric_room(seed):
    rng = np.random.default_rng(2000 + seed)
    poses = [{"x": float(3.5 + rng.uniform(-1, 1)), "y": float(3.5 + rng.uniform(-1, 1)),
              "yaw_deg": float(rng.uniform(-180, 180))} for _ in range(4)]
    return {"name": "symmetric", "poses": poses, "surfaces": room_walls(7.0, 7.0, 3.0)}


def long_corridor(seed):
    rng = np.random.default_rng(3000 + seed)
    L, W, H = 30.0, 2.2, 2.8
    surfaces = room_walls(L, W, H)
    for k in range(5):  # door niches 0.15 m deep, alternating sides
        x0 = 3.0 + 5.5 * k + rng.uniform(-1, 1)
        y = -0.15 if k % 2 == 0 else W
        surfaces.append({"type": "box", "class": "other", "min": [x0, y, 0], "max": [x0 + 1.0, y + 0.15, 2.1],
                         "omit": ["y+" if k % 2 == 0 else "y-"]})
    poses = [{"x": float(4.0 + 2.0 * k + rng.uniform(-0.3, 0.3)), "y": float(1.1 + rng.uniform(-0.3, 0.3)),
              "yaw_deg": float(rng.uniform(-8, 8))} for k in range(4)]
    return {"name": "long-corridor", "poses": poses, "surfaces": surfaces}


def shipped(path, poses_every):
    scene = json.load(open(os.path.join(ROOT, path)))
    scene.pop("odometry", None)
    scene["poses"] = scene["poses"][::poses_every]
    return scene


def with_pattern(scene, noise, seed):
    scene = dict(scene)
    scene["scan_pattern"] = dict(PATTERN, range_sigma=noise, seed=seed)
    return scene


def rot(axis, angle):
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s],
                     [y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s],
                     [z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c)]])


def random_error(rng, yaw_lo, yaw_hi):
    """A start error: translation up to 0.5 m (mostly horizontal), |yaw| in [lo, hi], roll/pitch up to 2 deg."""
    direction = rng.normal(size=3) * np.array([1, 1, 0.2])
    t = direction / np.linalg.norm(direction) * rng.uniform(0, 0.5)
    yaw = math.radians(rng.uniform(yaw_lo, yaw_hi)) * rng.choice([-1, 1])
    R = rot((0, 0, 1), yaw) @ rot((1, 0, 0), math.radians(rng.uniform(-2, 2))) @ rot((0, 1, 0),
                                                                                   math.radians(rng.uniform(-2, 2)))
    E = np.eye(4)
    E[:3, :3], E[:3, 3] = R, t
    return E


def read_tum(path):
    poses = []
    for line in open(path):
        v = line.split()
        if len(v) != 8 or line.startswith("#"):
            continue
        tx, ty, tz, qx, qy, qz, qw = map(float, v[1:])
        T = np.eye(4)
        T[:3, :3] = np.array([[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
                              [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
                              [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]])
        T[:3, 3] = [tx, ty, tz]
        poses.append(T)
    return poses


def quaternion(R):
    w = math.sqrt(max(0.0, 1 + R[0, 0] + R[1, 1] + R[2, 2])) / 2
    x = math.copysign(math.sqrt(max(0.0, 1 + R[0, 0] - R[1, 1] - R[2, 2])) / 2, R[2, 1] - R[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1 - R[0, 0] + R[1, 1] - R[2, 2])) / 2, R[0, 2] - R[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1 - R[0, 0] - R[1, 1] + R[2, 2])) / 2, R[1, 0] - R[0, 1])
    return x, y, z, w


def errors(T_true, T_est):
    E = np.linalg.inv(T_true) @ np.array(T_est)
    angle = math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(E[:3, :3]) - 1) / 2))))
    return 100 * float(np.linalg.norm(E[:3, 3])), angle


def run(cmd, env):
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stderr[-2000:]}")
    return p.stdout


def fresh_scenes(which):
    """The `fresh` split (session 35): scenes generated after the constants were set, every noise
    level on the generated rooms, pattern seed 3; for reporting, never for tuning."""
    out = []
    if "lab" in which:
        out.append(("lab", with_pattern(shipped("maps/lab.json", 1), 0.02, 3)))
    if "corridor" in which:
        out.append(("corridor", with_pattern(shipped("maps/corridor.json", 3), 0.03, 3)))
    if "symmetric" in which:
        out.append(("symmetric", with_pattern(symmetric_room(3), 0.03, 3)))
    if "long-corridor" in which:
        out.append(("long-corridor", with_pattern(long_corridor(3), 0.02, 3)))
    if "rooms" in which:
        for k, s in enumerate(range(21, 27)):
            out.append((f"room-{s}", with_pattern(random_room(s), [0.01, 0.02, 0.03][k % 3], 3)))
    return out


def scenes_for(split, which):
    if split == "fresh":
        return fresh_scenes(which)
    rooms = [1, 2, 3] if split == "tune" else [11, 12, 13]
    noise_seed = 1 if split == "tune" else 2
    noise = lambda k: [0.01, 0.02, 0.03][(k + noise_seed) % 3]
    out = []
    if "lab" in which:
        out.append(("lab", with_pattern(shipped("maps/lab.json", 1), noise(0), noise_seed)))
    if "corridor" in which:
        out.append(("corridor", with_pattern(shipped("maps/corridor.json", 3), noise(1), noise_seed)))
    if "symmetric" in which:
        out.append(("symmetric", with_pattern(symmetric_room(noise_seed), noise(2), noise_seed)))
    if "long-corridor" in which:
        out.append(("long-corridor", with_pattern(long_corridor(noise_seed), noise(0), noise_seed)))
    if "rooms" in which:
        for k, s in enumerate(rooms):
            out.append((f"room-{s}", with_pattern(random_room(s), noise(k + 1), s)))
    return out


def simulated_split(split, which, work, mlmap, env):
    """(name, scene directory) of the split's scenes, simulated into `work` where not there yet."""
    os.makedirs(work, exist_ok=True)
    out = []
    for name, scene in scenes_for(split, which):
        scene_dir = os.path.join(work, name)
        scene_json = os.path.join(work, name + ".json")
        if not os.path.exists(os.path.join(scene_dir, "poses_true.txt")):
            json.dump(scene, open(scene_json, "w"), indent=1)
            run([mlmap, "--quiet", "simulate", scene_json, "-o", scene_dir], env)
        out.append((name, scene_dir))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--peers-build", default="/work/build-peers")
    ap.add_argument("--split", choices=["report", "tune", "fresh"], default="report")
    ap.add_argument("--scenes", default="lab,corridor,symmetric,long-corridor,rooms")
    ap.add_argument("--pairs", type=int, default=3, help="consecutive pairs per scene")
    ap.add_argument("--starts", type=int, default=3, help="random starts per pair and start size")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--work", default="")
    ap.add_argument("--skip-peers", action="store_true")
    ap.add_argument("--plain", action="store_true", help="also the single ICP run (before the wide basin)")
    a = ap.parse_args()

    env = dict(os.environ, OMP_NUM_THREADS=str(a.threads))
    work = a.work or tempfile.mkdtemp(prefix="icp_stress_")
    os.makedirs(work, exist_ok=True)
    mlmap, bench = os.path.join(a.build, "mlmap"), os.path.join(a.build, "mlmap_bench")
    peers = []
    if not a.skip_peers:
        peers = [p for p in ["open3d_icp", "pcl_icp"] if os.path.exists(os.path.join(a.peers_build, p))]
        if not peers:
            print(f"(no peers in {a.peers_build}: mlmap only)")
    methods = ["mlmap"] + (["mlmap --plain"] if a.plain else []) + peers
    rows = []  # (scene, size, method, t_cm, r_deg, seconds, verified, attempts, unconstrained, first matched share)
    loads = [os.getloadavg()[0]]
    started = time.time()
    for name, scene_dir in simulated_split(a.split, a.scenes.split(","), work, mlmap, env):
        true = read_tum(os.path.join(scene_dir, "poses_true.txt"))
        rng = np.random.default_rng(sum(map(ord, name)) + {"tune": 0, "report": 7919, "fresh": 15838}[a.split])
        count = len(true) - 1
        chosen = sorted(set(np.linspace(0, count - 1, min(a.pairs, count)).round().astype(int)))
        jobs, starts_meta = {"pairs": []}, []
        for i in chosen:
            j = i + 1
            T_true = np.linalg.inv(true[i]) @ true[j]
            starts = []
            for size, lo, hi in (("small", 0, 10), ("large", 10, 30)):
                for _ in range(a.starts):
                    E = random_error(rng, lo, hi)
                    S = T_true.copy()
                    S[:3, :3] = T_true[:3, :3] @ E[:3, :3]  # turned about the sensor ...
                    S[:3, 3] = T_true[:3, 3] + E[:3, 3]     # ... and moved
                    starts.append(S)
                    starts_meta.append((f"{i}-{j}", size, T_true, S))
            jobs["pairs"].append({"id": f"{i}-{j}", "source": os.path.join(scene_dir, f"scan_{j:03d}.xyz"),
                                  "target": os.path.join(scene_dir, f"scan_{i:03d}.xyz"),
                                  "starts": [list(S.flatten()) for S in starts]})
        jobs_path = os.path.join(work, name + "_jobs.json")
        json.dump(jobs, open(jobs_path, "w"))
        for method in methods:
            loads.append(os.getloadavg()[0])
            if method.startswith("mlmap"):
                out = json.loads(run([bench, "icp-starts", jobs_path] + (["--plain"] if "plain" in method else []), env))
                for (pair, size, T_true, S), res in zip(starts_meta, out["runs"]):
                    t, r = errors(T_true, res["matrix"])
                    rows.append((name, size, method, t, r, res["seconds"]["total"], res["verified"], res["attempts"],
                                 res.get("unconstrained"), res.get("first_matched")))
                continue
            for k, (pair, size, T_true, S) in enumerate(starts_meta):
                i, j = map(int, pair.split("-"))
                poses = os.path.join(work, f"{name}_start{k}.txt")
                x, y, z, w = quaternion(S[:3, :3])
                with open(poses, "w") as f:
                    f.write("0 0 0 0 0 0 0 1\n")
                    f.write(f"1 {S[0, 3]!r} {S[1, 3]!r} {S[2, 3]!r} {x!r} {y!r} {z!r} {w!r}\n")
                res = json.loads(run([os.path.join(a.peers_build, method), os.path.join(scene_dir, f"scan_{j:03d}.xyz"),
                                      os.path.join(scene_dir, f"scan_{i:03d}.xyz"), "--poses", poses,
                                      "--source-index", "1", "--target-index", "0", "--threads", str(a.threads)], env))
                t, r = errors(T_true, res["relative_pose"]["matrix"])
                rows.append((name, size, method, t, r, res["seconds"]["total"], None, 1, None, None))
        print(f"  {name}: {len(starts_meta)} starts on {len(chosen)} pairs done ({time.time() - started:.0f} s)",
              file=sys.stderr)

    print(f"split: {a.split}; {a.pairs} pairs per scene, {a.starts} starts per pair and size; threads {a.threads}; "
          f"load average (1 min) {min(loads):.1f}-{max(loads):.1f} on {os.cpu_count()} CPUs; "
          f"{time.time() - started:.0f} s")
    print(f"success: final error < {SUCCESS_CM:g} cm and < {SUCCESS_DEG:g} deg; time = preparation + ICP per run "
          "(reading excluded), median")
    print()
    print("| scene | start | method | success | t err cm median | t err cm max | rot err deg median | "
          "rot err deg max | s/pair | verified (false) | unconstrained | ICP runs | first matched min |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    keys = []
    for row in rows:
        if (row[0], row[1]) not in keys:
            keys.append((row[0], row[1]))
    totals = {}
    for scene, size in keys + [("all", "small"), ("all", "large")]:
        for method in methods:
            sel = [r for r in rows if (r[0] == scene or scene == "all") and r[1] == size and r[2] == method]
            if not sel:
                continue
            ok = [r[3] < SUCCESS_CM and r[4] < SUCCESS_DEG for r in sel]
            ver = ""
            if sel[0][6] is not None:
                v = [r[6] for r in sel]
                false = sum(1 for r, good in zip(sel, ok) if r[6] and not good)
                ver = f"{sum(v)}/{len(v)} ({false})"
            runs = f"{np.mean([r[7] for r in sel]):.1f}" if method == "mlmap" else ""
            free = f"{sum(1 for r in sel if r[8])}" if method == "mlmap" else ""
            shares = [r[9] for r in sel if r[9] is not None]
            first = f"{min(shares):.2f}" if method == "mlmap" and shares else ""
            print(f"| {scene} | {size} | {method} | {sum(ok)}/{len(ok)} | {np.median([r[3] for r in sel]):.2f} | "
                  f"{max(r[3] for r in sel):.1f} | {np.median([r[4] for r in sel]):.3f} | "
                  f"{max(r[4] for r in sel):.2f} | {np.median([r[5] for r in sel]):.3f} | {ver} | {free} | {runs} | {first} |")
            totals[(scene, size, method)] = np.median([r[5] for r in sel])
    for peer in peers:
        ratio = [totals[("all", s, peer)] / totals[("all", s, "mlmap")] for s in ("small", "large")
                 if ("all", s, peer) in totals]
        print(f"\n{peer} time / mlmap time (median per run, small / large starts): "
              + " / ".join(f"{x:.1f}x" for x in ratio))
    json.dump(rows, open(os.path.join(work, f"rows_{a.split}.json"), "w"))
    print(f"\n(work directory: {work}; per run: rows_{a.split}.json)")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Plane detection per block: the real scans of ../shared/data beside the simulated lab and
corridor, CGAL's efficient RANSAC on the same real points side by side (issue 19: "plane
detection on the real scans no slower than on the simulated lab per block").

    /usr/bin/python3 bench/planes_speed.py [--build build] [--data ../shared/data] [--out out/speed]
        [--cells 0.05,0.1] [--lab-cells 0.02,0.05,0.1] [--repeat 5] [--peers /work/build-peers]
        [--only NAME,...] [--no-sim]

Maps: every scene of bench/real_clouds.py built as bench/real_data.py builds it (--no-octree,
3DTK registered first), and the lab and corridor of maps/ simulated with true poses and 1 cm
range noise (as bench/planes_bench.py). Each round runs `mlmap planes --threads 2` once on every
map in turn (so a busy spell of the shared machine falls on all maps alike); --repeat rounds.
Per map: the best and the median seconds (the planes JSON's total_s: everything after reading
the map), microseconds per map block (best / median), the median against the lab's at the same
cell size, the candidate planes drawn (by the last pass; each is scored and refitted up to 5 times), the median of every stage in microseconds per block (`first` is the noise stage: where
the blocks keep their points, a first detection that measures σ (its search stopped after 100
idle candidates), then the planes detected again with it on the same blocks and direction
vectors where σ leaves them as they are: `passes` 2), and with --peers CGAL's normals + detection on the scene's points (best of
--repeat; the points are the ones mlmap maps, so CGAL's time per point stands beside mlmap's).
Scenes without data are skipped with a message. Writes OUT/planes_speed.md too.
"""
import argparse, json, os, statistics, subprocess, sys, time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import real_data  # noqa: E402

STAGES = ("noise", "blocks", "directions", "index", "search", "patches", "merges", "labels")
STAGE_NAMES = ("first", "blocks", "dirs", "index", "search", "patches", "merges", "labels")


def simulated_maps(mlmap, out, cells_by_scene):
    """(name, cell, map path, points) of the simulated scenes (true poses, 1 cm range noise)."""
    maps = []
    for scene, cells in cells_by_scene.items():
        folder = os.path.join(out, scene)
        real_data.run([mlmap, "-q", "simulate", os.path.join(ROOT, "maps", scene + ".json"), "-o", folder])
        scans = sorted(os.path.join(folder, f) for f in os.listdir(folder) if f.startswith("scan_"))
        points = sum(1 for _ in open(os.path.join(folder, "all_world.xyz")))
        for cell in cells:
            path = os.path.join(out, f"{scene}-{cell:g}.mlmap")
            real_data.run([mlmap, "-q", "build", "-o", path, "--poses", os.path.join(folder, "poses_true.txt"),
                           "--cell-size", str(cell), "--range-sigma", "0.01", "--no-octree"] + scans)
            maps.append((f"sim {scene}", cell, path, points))
    return maps


def real_maps(mlmap, data, out, cells, only, peers, repeat):
    """(name, cell, map path, points) of the real scans, and CGAL's seconds per scene (best of `repeat`)."""
    import real_clouds
    features = {c: real_data.options_of(mlmap, c) for c in ("build", "label", "register")}
    maps, cgal = [], {}
    for name, scene, why in real_clouds.scenes(data):
        if only and name not in only:
            continue
        if scene is None:
            print(f"planes_speed: {name} skipped ({why})")
            continue
        folder = os.path.join(out, name)
        os.makedirs(folder, exist_ok=True)
        files, pose_file, up_options = real_data.scene_inputs(mlmap, scene, folder, features)
        world = scene.world()
        for cell in cells:
            path, _ = real_data.build_map(mlmap, folder, cell, files, pose_file, up_options, features)
            maps.append((name, cell, path, len(world)))
        if peers:
            cgal[name] = min(real_data.run_cgal(peers, folder, world)[2]["detect_s"] for _ in range(repeat))
    return maps, cgal


def time_maps(mlmap, maps, repeat, out):
    """Per map path, the planes JSONs of `repeat` rounds, each round over all maps in turn."""
    runs = {path: [] for _, _, path, _ in maps}
    result = os.path.join(out, "speed.planes.json")
    for _ in range(repeat):
        for _, _, path, _ in maps:
            real_data.run([mlmap, "-q", "planes", path, "--threads", "2", "--json", result])
            runs[path].append(json.load(open(result)))
    return runs


def table(maps, runs, cgal):
    lab = {}
    for name, cell, path, _ in maps:
        if name == "sim lab":
            j = runs[path]
            lab[cell] = statistics.median(r["timings"]["total_s"] for r in j) / j[0]["map"]["blocks"]
    head = ("| scene | cell m | points | blocks | candidates | passes | s best / median | µs/block best / median | × lab | " +
            " | ".join(STAGE_NAMES) + " | CGAL s | CGAL / mlmap |")
    lines = [head, "|---" * (head.count("|") - 1) + "|"]
    for name, cell, path, points in maps:
        j = runs[path]
        blocks = j[0]["map"]["blocks"]
        totals = [r["timings"]["total_s"] for r in j]
        best, median = min(totals), statistics.median(totals)
        stages = " | ".join(f"{1e6 * statistics.median(r['timings'].get(s + '_s', 0.0) for r in j) / blocks:.2f}"
                            for s in STAGES)
        versus_lab = f"{median / blocks / lab[cell]:.1f}" if cell in lab else "-"
        peer = f"{cgal[name]:.2f} | {cgal[name] / median:.1f}" if name in cgal else "- | -"
        lines.append(f"| {name} | {cell:g} | {points} | {blocks} | {j[0]['detection']['candidates']} | "
                     f"{j[0]['detection'].get('passes', '?')} | "
                     f"{best:.3f} / {median:.3f} | {1e6 * best / blocks:.2f} / {1e6 * median / blocks:.2f} | "
                     f"{versus_lab} | {stages} | {peer} |")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--data", default=os.path.join(os.path.dirname(ROOT), "shared", "data"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "speed"))
    ap.add_argument("--cells", default="0.05,0.1", help="cell sizes of the real scans")
    ap.add_argument("--lab-cells", default="0.02,0.05,0.1", help="cell sizes of the simulated lab (corridor: those >= 0.05)")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--peers", help="build directory of ../shared/peers (cgal_ransac); optional")
    ap.add_argument("--only", help="comma-separated real scene names")
    ap.add_argument("--no-sim", action="store_true", help="real scans only (no '× lab' column)")
    a = ap.parse_args()
    mlmap = os.path.join(a.build, "mlmap")
    if not os.access(mlmap, os.X_OK):
        raise SystemExit(f"planes_speed: no mlmap CLI at {mlmap} (build it first, or give --build)")
    peers = a.peers if a.peers and os.access(os.path.join(a.peers, "cgal_ransac"), os.X_OK) else None
    if a.peers and not peers:
        print(f"planes_speed: no cgal_ransac in {a.peers}, CGAL skipped")
    os.makedirs(a.out, exist_ok=True)
    maps = []
    if not a.no_sim:
        lab_cells = [float(c) for c in a.lab_cells.split(",")]
        maps += simulated_maps(mlmap, os.path.join(a.out, "sim"),
                               {"lab": lab_cells, "corridor": [c for c in lab_cells if c >= 0.05]})
    cgal = {}
    if os.path.isdir(a.data):
        real, cgal = real_maps(mlmap, a.data, a.out, [float(c) for c in a.cells.split(",")],
                               a.only.split(",") if a.only else None, peers, a.repeat)
        maps += real
    else:
        print(f"planes_speed: no data directory at {a.data}, real scans skipped")
    if not maps:
        return
    load_before = os.getloadavg()[0]
    runs = time_maps(mlmap, maps, a.repeat, a.out)
    text = table(maps, runs, cgal)
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    head = (f"`{' '.join(['bench/planes_speed.py'] + sys.argv[1:])}` at {commit or '?'}, {time.strftime('%Y-%m-%d %H:%M')}, "
            f"{a.repeat} rounds, load average {load_before:.1f} before / {os.getloadavg()[0]:.1f} after on {os.cpu_count()} cores\n")
    print(head)
    print(text)
    open(os.path.join(a.out, "planes_speed.md"), "w").write(head + "\n" + text)


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Planes in rooms that someone else's generator made: ../shared/peers/make_scene.py.

    /usr/bin/python3 bench/peer_scene.py [--build build] [--peers BUILD-PEERS] [--out out/peer-scene]
        [--sigmas 0.005,0.01,0.02] [--points 500000,150000] [--turns 0,7,23] [--seeds 1] [--outliers SHARE]
        [--build-args '--outlier-radius 0.1'] [--known-noise] [--keep]

make_scene.py (the peers' own, not this project's) draws a 10 x 8 x 3 m room, its table top, a
five-step stair (treads 28 cm, risers 17 cm) and a box, sampled uniformly at random with
isotropic Gaussian noise, uniform outliers in the room's volume (its default 0.5 %; --outliers
sets the share) and per-point plane labels: no scanner, no scan lines, so it holds
fixed nothing that the project's simulator holds (beams, line spacing, range noise along the
beam). Each room is turned about z by each turn and shifted by (1.3, 2.7) cm, so that neither
its walls nor its steps lie on cell boundaries; mlmap builds it (--identity, no range limits),
detects at 0.05 and 0.1 m cells and labels every point (`mlmap label`), and
../shared/peers/score.py scores the labels at point IoU >= 0.5 over the planes of >= 300 points
(--min-gt-points 300: patches touching none of them count neither way), and over the room's
walls, floor, ceiling and table top alone. Each room's files are removed once scored (--keep
keeps them: about 150 MB a room). With --peers, CGAL's efficient RANSAC on the same
cloud (its --eps at 3 sigma, the noise known here) side by side. --known-noise gives mlmap the
noise too (`build --range-sigma` at each room's sigma; by default `build` takes a scanner's 3 cm,
whose fusion gate is wider than a 5 cm cell and splits the 17 cm risers into level blocks).
Skipped with a message where ../shared/peers is absent.
"""
import argparse, json, os, subprocess, sys, time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PEERS = os.path.join(os.path.dirname(ROOT), "shared", "peers")
SHIFT = (0.013, 0.027)
STRUCTURAL = 6  # make_scene.py's ids 0-5 are floor, ceiling and walls, 6 the table top


def run(cmd):
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"peer_scene: {' '.join(cmd[:3])} ... failed:\n{done.stderr[-1500:]}")
    return done.stdout


def score(gt, labels):
    return json.loads(run(["/usr/bin/python3", os.path.join(PEERS, "score.py"), gt, labels, "--min-gt-points", "300"]))


def make_room(out, sigma, points, turn, seed, outliers=None):
    """The turned, shifted cloud (x y z label) and its structural-only truth."""
    tag = f"sigma{sigma:g}-points{points}-turn{turn:g}-seed{seed}" + (f"-outliers{outliers:g}" if outliers is not None else "")
    cloud = os.path.join(out, tag + ".xyz")
    structural = os.path.join(out, tag + ".structural.xyz")
    if not os.path.exists(structural):
        raw = os.path.join(out, tag + ".raw.xyz")
        run(["/usr/bin/python3", os.path.join(PEERS, "make_scene.py"), raw, "--points", str(points),
             "--sigma", str(sigma), "--seed", str(seed)] + ([] if outliers is None else ["--outliers", str(outliers)]))
        data = np.loadtxt(raw)
        a = np.radians(turn)
        rotation = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
        data[:, :3] = data[:, :3] @ rotation.T + np.array([SHIFT[0], SHIFT[1], 0.0])
        np.savetxt(cloud, data, fmt="%.5f %.5f %.5f %d")
        labels = data[:, 3].astype(int)
        data[:, 3] = np.where(labels <= STRUCTURAL, labels, -1)
        np.savetxt(structural, data, fmt="%.5f %.5f %.5f %d")
        os.remove(raw)
    return tag, cloud, structural


def mlmap_row(mlmap, out, tag, cloud, structural, cell, build_args=()):
    base = os.path.join(out, f"{tag}.cell{cell:g}")
    wide = ["--identity", "--min-range", "0", "--max-range", "1e4"]
    start = time.perf_counter()
    run([mlmap, "-q", "build", "--no-octree", "--cell-size", str(cell), "-o", base + ".mlmap"] + wide + list(build_args) +
        [cloud])
    built = time.perf_counter()
    run([mlmap, "-q", "planes", base + ".mlmap", "-o", base + ".planes.mlmap", "--json", base + ".planes.json"])
    detected = time.perf_counter()
    run([mlmap, "-q", "label", base + ".planes.mlmap", "-o", base + ".labels.xyz"] + wide + [cloud])
    row = dict(all=score(cloud, base + ".labels.xyz"), structural=score(structural, base + ".labels.xyz"),
               build_s=built - start, detect_s=detected - built)
    return row, [base + suffix for suffix in (".mlmap", ".planes.mlmap", ".labels.xyz")]


def cgal_row(peers, out, tag, cloud, structural, sigma):
    labels = os.path.join(out, tag + ".cgal.labels")
    result = json.loads(run([os.path.join(peers, "cgal_ransac"), cloud, "--eps", f"{3 * sigma:g}", "--angle", "20",
                             "--min-support", "200", "--max-planes", "60", "--labels", labels]))
    return dict(all=score(cloud, labels), structural=score(structural, labels),
                detect_s=result["seconds"]["normals"] + result["seconds"]["detect"]), [labels]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--peers", help="build directory of ../shared/peers (cgal_ransac); optional")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "peer-scene"))
    ap.add_argument("--sigmas", default="0.005,0.01,0.02")
    ap.add_argument("--points", default="500000,150000")
    ap.add_argument("--turns", default="0,7,23")
    ap.add_argument("--seeds", default="1")
    ap.add_argument("--outliers", type=float,
                    help="share of uniform outliers in the room's volume, labelled -1 (default: make_scene.py's, 0.005)")
    ap.add_argument("--build-args", default="", help="more options for `mlmap build`, e.g. '--outlier-radius 0.1'")
    ap.add_argument("--known-noise", action="store_true",
                    help="build each room with --range-sigma at its noise (as CGAL gets its --eps)")
    ap.add_argument("--keep", action="store_true", help="keep each room's clouds, maps and labels (~150 MB a room)")
    a = ap.parse_args()
    if not os.path.exists(os.path.join(PEERS, "make_scene.py")):
        print(f"peer_scene: skipped, no ../shared/peers/make_scene.py at {PEERS}")
        return
    mlmap = os.path.join(a.build, "mlmap")
    if not os.access(mlmap, os.X_OK):
        sys.exit(f"peer_scene: no mlmap binary at {mlmap} (build it, or give --build)")
    if a.peers and not os.access(os.path.join(a.peers, "cgal_ransac"), os.X_OK):
        sys.exit(f"peer_scene: no cgal_ransac in {a.peers} (build ../shared/peers, or leave out --peers)")
    os.makedirs(a.out, exist_ok=True)
    rows = []
    print("| noise cm | points | turn deg | seed | cell m | planes >= 300 pts | mlmap: patches, matched, F1 | "
          "walls, floor, ceiling, table: F1 | CGAL: F1, structural F1 | build + detect s (mlmap / CGAL) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for sigma in map(float, a.sigmas.split(",")):
        for points in map(int, a.points.split(",")):
            for turn in map(float, a.turns.split(",")):
                for seed in map(int, a.seeds.split(",")):
                    tag, cloud, structural = make_room(a.out, sigma, points, turn, seed, a.outliers)
                    made = [cloud, structural]
                    cgal = None
                    if a.peers:
                        cgal, files = cgal_row(a.peers, a.out, tag, cloud, structural, sigma)
                        made += files
                    for cell in (0.05, 0.1):
                        build_args = a.build_args.split() + (["--range-sigma", f"{sigma:g}"] if a.known_noise else [])
                        r, files = mlmap_row(mlmap, a.out, tag, cloud, structural, cell, build_args)
                        made += files
                        rows.append(dict(sigma=sigma, points=points, turn=turn, seed=seed, cell=cell, mlmap=r, cgal=cgal))
                        s, t = r["all"], r["structural"]
                        peer = f"{cgal['all']['f1']:.2f}, {cgal['structural']['f1']:.2f}" if cgal else "-"
                        peer_s = f"{cgal['detect_s']:.2f}" if cgal else "-"
                        print(f"| {100 * sigma:g} | {points} | {turn:g} | {seed} | {cell:g} | {s['gt_planes']} | "
                              f"{s['pred_planes']}, {s['matched']}, {s['f1']:.2f} | {t['f1']:.2f} | {peer} | "
                              f"{r['build_s'] + r['detect_s']:.2f} / {peer_s} |", flush=True)
                    if not a.keep:
                        for path in made:
                            if os.path.exists(path):
                                os.remove(path)
    for cell in (0.05, 0.1):
        mine = [r for r in rows if r["cell"] == cell]
        mean = np.mean([r["mlmap"]["all"]["f1"] for r in mine])
        structural = np.mean([r["mlmap"]["structural"]["f1"] for r in mine])
        print(f"\nmlmap {cell:g} m: mean F1 {mean:.3f} over {len(mine)} rooms, walls/floor/ceiling/table {structural:.3f}")
    if a.peers:
        cgal = [r for r in rows if r["cell"] == 0.05]
        print(f"CGAL: mean F1 {np.mean([r['cgal']['all']['f1'] for r in cgal]):.3f}, "
              f"walls/floor/ceiling/table {np.mean([r['cgal']['structural']['f1'] for r in cgal]):.3f}")
    load = os.getloadavg()
    given = (f" --outliers {a.outliers:g}" if a.outliers is not None else "") + (f" --build-args='{a.build_args}'" if a.build_args else "") + \
        (" --known-noise" if a.known_noise else "")
    print(f"\n`bench/peer_scene.py{given}` {time.strftime('%Y-%m-%d %H:%M')}, load average {load[0]:.1f} on {os.cpu_count()} cores")
    with open(os.path.join(a.out, "peer_scene.json"), "w") as f:
        json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()

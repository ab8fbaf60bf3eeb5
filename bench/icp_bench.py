#!/usr/bin/python3
"""mlmap's pairwise ICP against the ICP peers (Open3D, PCL point-to-plane) on the same scan pairs.

For each scene (default: maps/lab.json and maps/corridor.json, 1 cm range noise and the scene's
odometry drift) this
  1. simulates the scans (`mlmap simulate`),
  2. runs `mlmap_bench icp SCENE_DIR` (mlmap's pairwise registration with `mlmap register`'s
     defaults: crop, down-sampling, target voxel hash + normals, ICP; reading excluded),
  3. runs the peers' icp_eval.py twice: with the peers' defaults (0.05 m voxels) and with
     `--voxel 0.1` (mlmap's source voxel size),
and prints one table: per scene and method the median time per pair (down-sampling + normals or
target structure + ICP, median over --runs), the median and maximum translation and rotation
errors against poses_true.txt, and each peer's time over mlmap's.

Pairs and scoring are icp_eval.py's (source scan i+1, target scan i, start from the odometry
relative pose; E = inv(T_true)·T_est); its scoring functions are imported, not re-implemented.

Usage:
  bench/icp_bench.py [--build build] [--peers-build /tmp/build-peers]
                     [--peers-dir ../shared/peers] [--runs 3] [--threads 2] [--work DIR]
                     [--scenes maps/lab.json,maps/corridor.json] [--skip-peers]
"""
import argparse, importlib.util, json, os, subprocess, sys, tempfile
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def load_icp_eval(peers_dir):
    spec = importlib.util.spec_from_file_location("icp_eval", os.path.join(peers_dir, "icp_eval.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run(cmd, env):
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stderr}")
    return p.stdout


def score_mlmap(icp_eval, scene_dir, bench_json):
    true = icp_eval.read_tum(os.path.join(scene_dir, "poses_true.txt"))
    rows = []
    for pair in bench_json["pairs"]:
        i, j = pair["target"], pair["source"]
        t_err, r_err = icp_eval.errors(np.linalg.inv(true[i]) @ true[j], np.array(pair["matrix"]))
        rows.append(dict(pair=f"{i}-{j}", t_err_cm=t_err, r_err_deg=r_err, total_s=pair["seconds"]["total"],
                         src_down=pair["points"]["source_down"], tgt_down=pair["points"]["target_down"]))
    return rows


def summarise(rows):
    t = [r["t_err_cm"] for r in rows]
    a = [r["r_err_deg"] for r in rows]
    s = [r["total_s"] for r in rows]
    return dict(time=float(np.median(s)), t_med=float(np.median(t)), t_max=max(t), r_med=float(np.median(a)),
                r_max=max(a), src=int(np.median([r["src_down"] for r in rows])),
                tgt=int(np.median([r["tgt_down"] for r in rows])))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--peers-build", default="/tmp/build-peers")
    ap.add_argument("--peers-dir", default=os.path.join(ROOT, "..", "shared", "peers"))
    ap.add_argument("--scenes", default="maps/lab.json,maps/corridor.json")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--work", default="", help="keep the simulated scenes and JSON here")
    ap.add_argument("--skip-peers", action="store_true", help="mlmap only (while iterating)")
    a = ap.parse_args()

    icp_eval = load_icp_eval(a.peers_dir)
    env = dict(os.environ, OMP_NUM_THREADS=str(a.threads))
    work = a.work or tempfile.mkdtemp(prefix="icp_bench_")
    mlmap = os.path.join(a.build, "mlmap")
    bench = os.path.join(a.build, "mlmap_bench")
    peer_settings = [("defaults (0.05 m voxels)", []), ("--voxel 0.1", ["--voxel", "0.1"])]

    table = []  # (scene, method, summary)
    for scene_json in a.scenes.split(","):
        name = os.path.splitext(os.path.basename(scene_json))[0]
        scene_dir = os.path.join(work, name)
        if not os.path.exists(os.path.join(scene_dir, "poses_true.txt")):
            run([mlmap, "simulate", os.path.join(ROOT, scene_json), "-o", scene_dir], env)
        out = json.loads(run([bench, "icp", scene_dir, "--runs", str(a.runs)], env))
        json.dump(out, open(os.path.join(work, f"{name}_mlmap.json"), "w"), indent=1)
        rows = score_mlmap(icp_eval, scene_dir, out)
        table.append((name, "mlmap", summarise(rows)))
        if a.skip_peers:
            continue
        for label, args in peer_settings:
            out_dir = os.path.join(work, f"{name}_peers_{'default' if not args else 'voxel0.1'}")
            run(["/usr/bin/python3", os.path.join(a.peers_dir, "icp_eval.py"), a.peers_build, scene_dir,
                 "--runs", str(a.runs), "--out", out_dir, "--"] + args + ["--threads", str(a.threads)], env)
            summary = json.load(open(os.path.join(out_dir, "summary.json")))["results"]
            for peer in ("open3d_icp", "pcl_icp"):
                table.append((name, f"{peer} {label}", summarise(summary[peer])))

    print(f"threads: {a.threads}; runs: {a.runs} (median); load average: {os.getloadavg()[0]:.2f} (1 min)")
    print("time = down-sampling + normals/target structure + ICP per pair, reading excluded")
    print()
    print("| scene | method | points src/tgt (down) | median s/pair | peer/mlmap | median t err cm | "
          "max t err cm | median rot err deg | max rot err deg |")
    print("|---|---|---|---|---|---|---|---|---|")
    mlmap_time = {scene: s["time"] for scene, method, s in table if method == "mlmap"}
    for scene, method, s in table:
        ratio = "1" if method == "mlmap" else f"{s['time'] / mlmap_time[scene]:.1f}x"
        print(f"| {scene} | {method} | {s['src']}/{s['tgt']} | {s['time']:.3f} | {ratio} | {s['t_med']:.2f} | "
              f"{s['t_max']:.2f} | {s['r_med']:.3f} | {s['r_max']:.3f} |")
    print(f"\n(work directory: {work})")


if __name__ == "__main__":
    main()

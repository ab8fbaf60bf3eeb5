#!/usr/bin/python3
"""mlmap's pairwise ICP against the ICP peers (Open3D, PCL point-to-plane) on the same scan pairs.

For each scene (default: maps/lab.json and maps/corridor.json, 1 cm range noise and the scene's
odometry drift) this
  1. simulates the scans (`mlmap simulate`),
  2. runs `mlmap_bench icp SCENE_DIR` (mlmap's pairwise registration with `mlmap register`'s
     defaults: crop, down-sampling, target voxel hash + normals, ICP; reading excluded),
  3. runs the peers' icp_eval.py twice: with the peers' defaults (0.05 m voxels) and with
     `--voxel 0.1` (mlmap's source voxel size),
and prints one table: per scene and method the time per pair (down-sampling + normals or target
structure + ICP, reading excluded), the median and maximum translation and rotation errors
against poses_true.txt, and each peer's time over mlmap's.

The machine is usually shared, so the methods run in --rounds interleaved rounds (mlmap, the
peers at their defaults, the peers at 0.1 m, again, ...), one run per pair and round. Two time
figures per method: the median over pairs of each pair's median over rounds (as icp_eval.py's
own --runs median), and of each pair's minimum over rounds (the least disturbed run: what the
code costs when it has the cores to itself). Errors are from the first round (every method is
deterministic).

Pairs and scoring are icp_eval.py's (source scan i+1, target scan i, start from the odometry
relative pose; E = inv(T_true)·T_est); its scoring functions are imported, not re-implemented.

Usage:
  bench/icp_bench.py [--build build] [--peers-build /tmp/build-peers]
                     [--peers-dir ../shared/peers] [--rounds 5] [--threads 2] [--work DIR]
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


def errors_of(icp_eval, true, i, j, matrix):
    return icp_eval.errors(np.linalg.inv(true[i]) @ true[j], np.array(matrix))


def mlmap_round(icp_eval, true, bench_json):
    """{pair: (total seconds, t err cm, rot err deg, source points, target points)}"""
    out = {}
    for p in bench_json["pairs"]:
        i, j = p["target"], p["source"]
        t_err, r_err = errors_of(icp_eval, true, i, j, p["matrix"])
        out[f"{i}-{j}"] = (p["seconds"]["total"], t_err, r_err, p["points"]["source_down"],
                           p["points"]["target_down"])
    return out


def peer_round(icp_eval, true, out_dir, peer):
    out = {}
    for name in sorted(os.listdir(out_dir)):
        if not (name.startswith(peer + "_") and name.endswith(".json")):
            continue
        pair = name[len(peer) + 1:-5]
        i, j = map(int, pair.split("-"))
        res = json.load(open(os.path.join(out_dir, name)))[0]  # --runs 1: one result
        t_err, r_err = errors_of(icp_eval, true, i, j, res["relative_pose"]["matrix"])
        out[pair] = (res["seconds"]["total"], t_err, r_err, res["points"]["source_down"],
                     res["points"]["target_down"])
    return out


def summarise(rounds):
    """rounds: list of {pair: (seconds, t_err, r_err, src, tgt)}; errors from the first round."""
    pairs = sorted(rounds[0], key=lambda p: tuple(map(int, p.split("-"))))
    first = rounds[0]
    per_pair = {p: [r[p][0] for r in rounds] for p in pairs}
    t = [first[p][1] for p in pairs]
    a = [first[p][2] for p in pairs]
    return dict(time_median=float(np.median([np.median(v) for v in per_pair.values()])),
                time_min=float(np.median([min(v) for v in per_pair.values()])),
                t_med=float(np.median(t)), t_max=max(t), r_med=float(np.median(a)), r_max=max(a),
                src=int(np.median([first[p][3] for p in pairs])), tgt=int(np.median([first[p][4] for p in pairs])))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--peers-build", default="/tmp/build-peers")
    ap.add_argument("--peers-dir", default=os.path.join(ROOT, "..", "shared", "peers"))
    ap.add_argument("--scenes", default="maps/lab.json,maps/corridor.json")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--work", default="", help="keep the simulated scenes and JSON here")
    ap.add_argument("--skip-peers", action="store_true", help="mlmap only (while iterating)")
    a = ap.parse_args()

    icp_eval = load_icp_eval(a.peers_dir)
    env = dict(os.environ, OMP_NUM_THREADS=str(a.threads))
    work = a.work or tempfile.mkdtemp(prefix="icp_bench_")
    mlmap = os.path.join(a.build, "mlmap")
    bench = os.path.join(a.build, "mlmap_bench")
    peer_settings = [("defaults (0.05 m voxels)", "default", []), ("--voxel 0.1", "voxel0.1", ["--voxel", "0.1"])]
    peers = [] if a.skip_peers else ["open3d_icp", "pcl_icp"]

    table = []  # (scene, method, summary)
    loads = []
    for scene_json in a.scenes.split(","):
        name = os.path.splitext(os.path.basename(scene_json))[0]
        scene_dir = os.path.join(work, name)
        if not os.path.exists(os.path.join(scene_dir, "poses_true.txt")):
            run([mlmap, "simulate", os.path.join(ROOT, scene_json), "-o", scene_dir], env)
        true = icp_eval.read_tum(os.path.join(scene_dir, "poses_true.txt"))
        rounds = {"mlmap": []}
        for r in range(a.rounds):
            loads.append(os.getloadavg()[0])
            out = json.loads(run([bench, "icp", scene_dir, "--runs", "1"], env))
            json.dump(out, open(os.path.join(work, f"{name}_mlmap_r{r}.json"), "w"), indent=1)
            rounds["mlmap"].append(mlmap_round(icp_eval, true, out))
            for label, tag, args in (peer_settings if peers else []):
                out_dir = os.path.join(work, f"{name}_peers_{tag}_r{r}")
                run(["/usr/bin/python3", os.path.join(a.peers_dir, "icp_eval.py"), a.peers_build, scene_dir,
                     "--runs", "1", "--out", out_dir, "--"] + args + ["--threads", str(a.threads)], env)
                for peer in peers:
                    rounds.setdefault(f"{peer} {label}", []).append(peer_round(icp_eval, true, out_dir, peer))
        for method, rs in rounds.items():
            table.append((name, method, summarise(rs)))

    print(f"threads: {a.threads}; rounds: {a.rounds}; load average (1 min) at the rounds: "
          f"{min(loads):.2f}-{max(loads):.2f} on {os.cpu_count()} CPUs")
    print("time per pair = down-sampling + normals/target structure + ICP, reading excluded;")
    print("'median' = median over pairs of each pair's median over rounds, 'min' = ... of its minimum")
    print()
    print("| scene | method | points src/tgt (down) | s/pair median | s/pair min | peer/mlmap median | "
          "peer/mlmap min | t err cm median | t err cm max | rot err deg median | rot err deg max |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    ref = {scene: s for scene, method, s in table if method == "mlmap"}
    for scene, method, s in table:
        r = ref[scene]
        ratio_med = "1" if method == "mlmap" else f"{s['time_median'] / r['time_median']:.1f}x"
        ratio_min = "1" if method == "mlmap" else f"{s['time_min'] / r['time_min']:.1f}x"
        print(f"| {scene} | {method} | {s['src']}/{s['tgt']} | {s['time_median']:.3f} | {s['time_min']:.3f} | "
              f"{ratio_med} | {ratio_min} | {s['t_med']:.2f} | {s['t_max']:.2f} | {s['r_med']:.3f} | "
              f"{s['r_max']:.3f} |")
    print(f"\n(work directory: {work})")


if __name__ == "__main__":
    main()

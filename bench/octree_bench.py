#!/usr/bin/python3
"""The OcTree layer beside OctoMap's and Bonxai's insertion on the same scans (issue 21).

    /usr/bin/python3 bench/octree_bench.py [--build build] [--peers /work/build-peers]
        [--scene maps/lab.json] [--resolutions 0.05,0.1] [--rounds 3] [--out DIR]

Simulates the scene (true poses), then per resolution runs, in alternating rounds, each
under /usr/bin/time -v:
  mlmap     `mlmap_bench octree`: Map::insertIntoOctree alone (one ray per end voxel,
            OctoMap's discretized semantics), all OpenMP threads, waiting passively as
            the CLI does (OMP_WAIT_POLICY=passive unless set: apps/passive_wait.cpp);
  mlmap-1t  the same on one thread (OMP_NUM_THREADS=1);
  octomap   ../shared/peers' octomap_insert --discrete (insertPointCloud, discretize=true);
  bonxai    ../shared/peers' bonxai_insert (ProbabilisticMap, one ray per end voxel).
Prints points/s (best and median of the rounds; insertion only, file reading excluded),
each as a ratio to mlmap's, and the peak RSS of each process. Then the peak RSS of a whole
`mlmap build` beside octomap_insert's, and the .bt sizes (`mlmap export --bt` against
octomap_insert --out). The machine may be shared: only the ratios within one run hold;
the load average is printed with them.
"""
import argparse, glob, json, os, re, statistics, subprocess, sys, tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def timed(cmd, env=None):
    """Runs cmd under /usr/bin/time -v: its JSON stdout and its peak RSS in MB."""
    result = subprocess.run(["/usr/bin/time", "-v"] + cmd, capture_output=True, text=True, env=env)
    if result.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{result.stderr[-2000:]}")
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", result.stderr)
    text = result.stdout
    data = json.loads(text[text.index("{"):]) if "{" in text else {}
    return data, (int(rss.group(1)) / 1024.0 if rss else float("nan"))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--peers", default="/work/build-peers")
    parser.add_argument("--scene", default=os.path.join(ROOT, "maps", "lab.json"))
    parser.add_argument("--resolutions", default="0.05,0.1")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    mlmap = os.path.join(args.build, "mlmap")
    bench = os.path.join(args.build, "mlmap_bench")
    out = args.out or tempfile.mkdtemp(prefix="octree-bench-")
    os.makedirs(out, exist_ok=True)
    if not glob.glob(os.path.join(out, "scan_*.xyz")):
        subprocess.run([mlmap, "--quiet", "simulate", args.scene, "-o", out], check=True)
    scans = sorted(glob.glob(os.path.join(out, "scan_*.xyz")))
    poses = os.path.join(out, "poses_true.txt")
    peers = {}
    for name in ("octomap_insert", "bonxai_insert"):
        path = os.path.join(args.peers, name)
        if os.path.exists(path):
            peers[name] = path
        else:
            print(f"({name} not built in {args.peers}: left out)")
    passive = dict(os.environ)
    passive.setdefault("OMP_WAIT_POLICY", "passive")
    one_thread = dict(passive, OMP_NUM_THREADS="1")
    print(f"{args.scene}: {len(scans)} scans; load average {os.getloadavg()[0]:.1f} "
          f"on {os.cpu_count()} CPUs at the start")
    for res in [float(r) for r in args.resolutions.split(",")]:
        programs = {
            "mlmap": ([bench, "octree", "--poses", poses, "--resolution", str(res)] + scans, passive),
            "mlmap-1t": ([bench, "octree", "--poses", poses, "--resolution", str(res)] + scans, one_thread),
        }
        if "octomap_insert" in peers:
            programs["octomap"] = ([peers["octomap_insert"], "--poses", poses, "--resolution", str(res),
                                    "--discrete"] + scans, None)
        if "bonxai_insert" in peers:
            programs["bonxai"] = ([peers["bonxai_insert"], "--poses", poses, "--resolution", str(res)] + scans, None)
        rates = {name: [] for name in programs}
        rss = {name: 0.0 for name in programs}
        points = 0
        for _ in range(args.rounds):
            for name, (cmd, env) in programs.items():
                data, peak = timed(cmd, env)
                rates[name].append(data["points_per_s"])
                rss[name] = max(rss[name], peak)
                points = data.get("points", points)
        base_best = max(rates["mlmap"])
        base_median = statistics.median(rates["mlmap"])
        print(f"\n{res:g} m, {points} points, {args.rounds} rounds (load {os.getloadavg()[0]:.1f}):")
        print(f"  {'program':10} {'M pt/s best':>12} {'median':>8} {'best/mlmap':>11} {'median/mlmap':>13} {'peak RSS MB':>12}")
        for name in programs:
            best, median = max(rates[name]), statistics.median(rates[name])
            print(f"  {name:10} {best / 1e6:12.2f} {median / 1e6:8.2f} {best / base_best:11.2f} "
                  f"{median / base_median:13.2f} {rss[name]:12.0f}")
        # A whole build (blocks, OcTree, file) and the .bt, against OctoMap's.
        mlmap_file = os.path.join(out, f"bench_{res:g}.mlmap")
        bt = os.path.join(out, f"bench_{res:g}.bt")
        _, build_rss = timed([mlmap, "--quiet", "build", "--poses", poses, "--cell-size", str(res),
                              "-o", mlmap_file] + scans)
        subprocess.run([mlmap, "--quiet", "export", mlmap_file, "--bt", bt], check=True)
        line = f"  mlmap build peak RSS {build_rss:.0f} MB, its .bt {os.path.getsize(bt) / 1e6:.2f} MB"
        if "octomap_insert" in peers:
            octomap_bt = os.path.join(out, f"octomap_{res:g}.bt")
            _, octomap_rss = timed([peers["octomap_insert"], "--poses", poses, "--resolution", str(res),
                                    "--discrete", "--out", octomap_bt] + scans)
            line += (f"; octomap_insert --discrete peak RSS {octomap_rss:.0f} MB, "
                     f"its .bt {os.path.getsize(octomap_bt) / 1e6:.2f} MB")
        print(line)


if __name__ == "__main__":
    main()

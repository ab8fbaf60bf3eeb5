#!/usr/bin/python3
"""The real-scan figures across detection seeds: how much of a change is the search's chance.

    /usr/bin/python3 bench/real_seeds.py [--build build] [--against OTHER_BUILD] [--seeds 1,2,3]
        [--out out/real-seeds] [--only NAME,...]

eRMSM draws its candidates at random (`mlmap planes --seed`, default 1), and which plane is
accepted first decides what the others can take. On the real scans of ../shared/data that moves
bench/real_data.py's counts by more than most changes to the detector do: the same code found
28, 28 and 25 of the 37 marked walls, floors and ceilings at 5 cm cells with seeds 1, 2 and 3
(2026-12-03). So a change is judged here on several seeds: bench/real_data.py runs once per
seed (and per build, with --against), and this prints, per build and cell size, each seed's
totals and their sum, and with --against which marked surfaces pass in one build and not in
the other, seed by seed. Skipped with a message where ../shared/data is absent.
"""
import argparse, json, os, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

# real_data.json's totals per method, as real_data.py counts them: (column, found key, of key).
TOTALS = (("found", "found", "marked"), ("walls/floor/ceiling", "structural_found", "structural"),
          ("others", "other_found", "other"), ("rms", "rms_ok", "marked"), ("stray patches", "stray", None))
CELLS = ("mlmap 0.05", "mlmap 0.1")


def passing(result):
    """{(scene, surface, method)} of the marked surfaces real_data.py found."""
    return {(v["scene"], v["surface"], v["method"]) for v in result["surfaces"] if v["found"]}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--against", help="a second build directory, run on the same seeds and compared")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "real-seeds"))
    ap.add_argument("--only", help="comma-separated scene names (real_data.py's)")
    ap.add_argument("--data", default=os.path.join(os.path.dirname(ROOT), "shared", "data"))
    a = ap.parse_args()
    if not os.path.isdir(a.data):
        print(f"real_seeds: skipped, no data directory at {a.data}")
        return
    builds = [("build", a.build)] + ([("against", a.against)] if a.against else [])
    seeds = [int(s) for s in a.seeds.split(",")]
    reports = {}
    for tag, build in builds:
        for seed in seeds:
            out = os.path.join(a.out, f"{tag}-seed{seed}")
            cmd = [sys.executable, os.path.join(HERE, "real_data.py"), "--build", build, "--out", out,
                   "--data", a.data, f"--planes-args=--seed {seed}"] + (["--only", a.only] if a.only else [])
            stale = os.path.join(out, "real_data.json")
            if os.path.exists(stale):
                os.remove(stale)  # a result is this run's or none
            print(f"real_seeds: {build}, seed {seed}", file=sys.stderr, flush=True)
            done = subprocess.run(cmd, capture_output=True, text=True)
            if done.returncode != 0:
                raise SystemExit(f"real_seeds: real_data.py failed for {build}, seed {seed}:\n{done.stderr[-2000:]}")
            reports[(tag, seed)] = os.path.join(out, "real_data.json")
            if not os.path.exists(reports[(tag, seed)]):
                raise SystemExit(f"real_seeds: real_data.py scored no scene for {build}, seed {seed}:\n{done.stdout[-2000:]}")
    results = {key: json.load(open(path)) for key, path in reports.items()}
    print("| build | seed | " + " | ".join(f"{name} 0.05 / 0.1" for name, _, _ in TOTALS) + " |")
    print("|---|---|" + "---|" * len(TOTALS))
    for tag, build in builds:
        sums = {name: [0, 0] for name, _, _ in TOTALS}
        for seed in seeds:
            totals = results[(tag, seed)]["totals"]
            row = []
            for name, key, _ in TOTALS:
                values = [totals[cell][key] if cell in totals else 0 for cell in CELLS]
                sums[name] = [total + value for total, value in zip(sums[name], values)]
                row.append(" / ".join(map(str, values)))
            print(f"| {build} | {seed} | " + " | ".join(row) + " |")
        first = results[(tag, seeds[0])]["totals"]
        of = [" of " + " / ".join(str(len(seeds) * first[cell][of_key]) for cell in CELLS if cell in first)
              if of_key else "" for _, _, of_key in TOTALS]
        print(f"| {build} | sum | " + " | ".join(" / ".join(map(str, sums[name])) + tail
                                              for (name, _, _), tail in zip(TOTALS, of)) + " |")
    if a.against:
        print()
        for seed in seeds:
            first, second = passing(results[("build", seed)]), passing(results[("against", seed)])
            print(f"seed {seed}: found only with {a.build}: {sorted(first - second)}; only with {a.against}: {sorted(second - first)}")

if __name__ == "__main__":
    main()

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
import argparse, os, re, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

# real_data.md's totals, as totals_table writes them.
TOTALS = (("found", r"\| surfaces found \| (.*) \|"),
          ("walls/floor/ceiling", r"\| walls, floor, ceiling: >= 90 % on a patch joining no other \| (.*) \|"),
          ("others", r"\| the others \(tables, treads, steps\): >= 70 % \| (.*) \|"),
          ("rms", r"\| RMS to the patch's plane within 0.5 cm of the points' own fit \| (.*) \|"),
          ("stray patches", r"\| patches on no marked surface \| (.*) \|"))
STRUCTURAL = ("wall", "floor", "ceiling")


def totals(report):
    """{figure: [value per mlmap column]} from a real_data.md (the counts before "of")."""
    text = open(report).read().split("#### all scans")[-1]
    out = {}
    for name, pattern in TOTALS:
        match = re.search(pattern, text)
        out[name] = [int(cell.split(" of ")[0]) for cell in match.group(1).split(" | ")] if match else []
    return out


def passing(report):
    """{(scene, surface, cell): True} for the marked surfaces found, from the per-scene tables."""
    found, scene = set(), None
    for line in open(report):
        if line.startswith("#### "):
            scene = line[5:].split(":")[0]
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if not line.startswith("| ") or len(cells) < 11 or cells[1] not in STRUCTURAL + ("table", "tread", "step"):
            continue
        need = 90 if cells[1] in STRUCTURAL else 70
        for cell, (share, joins) in (("0.05", (3, 5)), ("0.1", (7, 9))):
            if cells[share].isdigit() and int(cells[share]) >= need and cells[joins] == "0":
                found.add((scene, cells[0], cell))
    return found


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
            print(f"real_seeds: {build}, seed {seed}", file=sys.stderr, flush=True)
            done = subprocess.run(cmd, capture_output=True, text=True)
            if done.returncode != 0:
                raise SystemExit(f"real_seeds: real_data.py failed for {build}, seed {seed}:\n{done.stderr[-2000:]}")
            reports[(tag, seed)] = os.path.join(out, "real_data.md")
    print("| build | seed | " + " | ".join(f"{name} 0.05 / 0.1" for name, _ in TOTALS) + " |")
    print("|---|---|" + "---|" * len(TOTALS))
    for tag, build in builds:
        sums = {name: [0, 0] for name, _ in TOTALS}
        for seed in seeds:
            figures = totals(reports[(tag, seed)])
            for name, _ in TOTALS:
                for k, value in enumerate(figures[name][:2]):
                    sums[name][k] += value
            print(f"| {build} | {seed} | " + " | ".join(" / ".join(map(str, figures[name][:2])) for name, _ in TOTALS) + " |")
        print(f"| {build} | sum | " + " | ".join(" / ".join(map(str, sums[name])) for name, _ in TOTALS) + " |")
    if a.against:
        print()
        for seed in seeds:
            first, second = passing(reports[("build", seed)]), passing(reports[("against", seed)])
            print(f"seed {seed}: found only with {a.build}: {sorted(first - second)}; only with {a.against}: {sorted(second - first)}")


if __name__ == "__main__":
    main()

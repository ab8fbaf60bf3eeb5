#!/usr/bin/python3
"""The real-scan figures across detection seeds and grid placements: how much of a change is chance.

    /usr/bin/python3 bench/real_seeds.py [--build build] [--against OTHER_BUILD] [--seeds 1,2,3]
        [--turns 0] [--shifts 0,0] [--keeps 1] [--placements | --densities] [--out out/real-seeds]
        [--only NAME,...]

eRMSM draws its candidates at random (`mlmap planes --seed`, default 1), and which plane is
accepted first decides what the others can take. On the real scans of ../shared/data that moves
bench/real_data.py's counts by more than most changes to the detector do: the same code found
28, 28 and 25 of the 37 marked walls, floors and ceilings at 5 cm cells with seeds 1, 2 and 3
(2026-12-03). The cell grid's placement moves them as much: every real scan lies in the frame its
authors gave it, the frame every constant of the detector was tried on, and the same scans turned
by 10-40° about the vertical or moved by a fraction of a cell lose up to 16 of their 64 surfaces at
10 cm cells (session 47; a surface a cell wide or two layers a cell apart comes out one way or the
other with the grid). So a change is judged here on several draws: bench/real_data.py runs once
per seed, turn (deg, about the up axis) and shift (m, "x,y"; --turns and --shifts list them,
';'-separated for shifts), per build with --against, and this prints, per build and cell size, each
draw's totals and their sum, and with --against which marked surfaces pass in one build and not in
the other, draw by draw. --placements is --seeds 1 --turns 0,10,25,40 --shifts "0,0;0.013,0.027;0.05,0.05"
(twelve placements, the native one among them). --keeps lists shares of each scan's points kept
(real_data.py --keep, the thinning drawn with the draw's seed); --densities is --seeds 1,2,3
--keeps 1,0.5,0.25 (scan density, which no constant was tried on either: a seed then draws both
the detection and the thinning). Skipped with a message where ../shared/data is absent.
"""
import argparse, collections, json, os, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

# real_data.json's totals per method, as real_data.py counts them: (column, found key, of key).
TOTALS = (("found", "found", "marked"), ("walls/floor/ceiling", "structural_found", "structural"),
          ("others", "other_found", "other"), ("rms", "rms_ok", "marked"), ("stray patches", "stray", None))
CELLS = ("mlmap 0.05", "mlmap 0.1")


class Draw(collections.namedtuple("Draw", "seed turn shift keep")):
    """One run of real_data.py: a detection seed, a turn (deg) and a shift ("x,y", m) of the scenes,
    the share of their points kept."""

    def name(self):
        placed = "" if self.turn == 0.0 and self.shift in ("0,0", "0.0,0.0") else f"-turn{self.turn:g}-shift{self.shift}"
        thinned = "" if self.keep == 1.0 else f"-keep{self.keep:g}"
        return f"seed{self.seed}{placed}{thinned}"


def passing(result):
    """{(scene, surface, method)} of the marked surfaces real_data.py found."""
    return {(v["scene"], v["surface"], v["method"]) for v in result["surfaces"] if v["found"]}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--against", help="a second build directory, run on the same seeds and compared")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--turns", default="0", help="deg about the up axis, comma-separated (real_data.py --turn)")
    ap.add_argument("--shifts", default="0,0", help="m, 'x,y' pairs separated by ';' (real_data.py --shift)")
    ap.add_argument("--placements", action="store_true",
                    help="seed 1 on twelve grid placements: turns 0,10,25,40 by shifts 0,0; 0.013,0.027; 0.05,0.05")
    ap.add_argument("--keeps", default="1", help="shares of each scan's points kept, comma-separated (real_data.py --keep)")
    ap.add_argument("--densities", action="store_true",
                    help="seeds 1,2,3 at each of keeps 1,0.5,0.25 (the scans thinned, the draw seeded by the seed)")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "real-seeds"))
    ap.add_argument("--only", help="comma-separated scene names (real_data.py's)")
    ap.add_argument("--data", default=os.path.join(os.path.dirname(ROOT), "shared", "data"))
    a = ap.parse_args()
    if not os.path.isdir(a.data):
        print(f"real_seeds: skipped, no data directory at {a.data}")
        return
    builds = [("build", a.build)] + ([("against", a.against)] if a.against else [])
    if a.placements and a.densities:
        raise SystemExit("real_seeds: --placements and --densities are two benchmarks: give one")
    if a.placements:
        a.seeds, a.turns, a.shifts = "1", "0,10,25,40", "0,0;0.013,0.027;0.05,0.05"
    if a.densities:
        a.seeds, a.keeps = "1,2,3", "1,0.5,0.25"
    try:
        draws = [Draw(int(seed), float(turn), shift.strip(), float(keep)) for keep in a.keeps.split(",")
                 for seed in a.seeds.split(",") for turn in a.turns.split(",") for shift in a.shifts.split(";")]
        for draw in draws:
            if len([float(v) for v in draw.shift.split(",")]) != 2:
                raise ValueError(draw.shift)
            if not 0.0 < draw.keep <= 1.0:
                raise ValueError(f"keep {draw.keep:g} is no share in (0, 1]")
    except ValueError as error:
        raise SystemExit(f"real_seeds: --seeds, --turns, --shifts and --keeps take numbers (a shift is 'x,y'): {error}")
    reports = {}
    for tag, build in builds:
        for draw in draws:
            out = os.path.join(a.out, f"{tag}-{draw.name()}")
            cmd = [sys.executable, os.path.join(HERE, "real_data.py"), "--build", build, "--out", out,
                   "--data", a.data, f"--planes-args=--seed {draw.seed}", "--turn", f"{draw.turn:g}",
                   "--shift", draw.shift, "--keep", f"{draw.keep:g}", "--keep-seed", str(draw.seed)] + \
                (["--only", a.only] if a.only else [])
            stale = os.path.join(out, "real_data.json")
            if os.path.exists(stale):
                os.remove(stale)  # a result is this run's or none
            print(f"real_seeds: {build}, {draw.name()}", file=sys.stderr, flush=True)
            done = subprocess.run(cmd, capture_output=True, text=True)
            if done.returncode != 0:
                raise SystemExit(f"real_seeds: real_data.py failed for {build}, {draw.name()}:\n{done.stderr[-2000:]}")
            reports[(tag, draw)] = os.path.join(out, "real_data.json")
            if not os.path.exists(reports[(tag, draw)]):
                raise SystemExit(f"real_seeds: real_data.py scored no scene for {build}, {draw.name()}:\n{done.stdout[-2000:]}")
    results = {key: json.load(open(path)) for key, path in reports.items()}
    print("| build | draw | " + " | ".join(f"{name} 0.05 / 0.1" for name, _, _ in TOTALS) + " |")
    print("|---|---|" + "---|" * len(TOTALS))
    for tag, build in builds:
        sums = {name: [0, 0] for name, _, _ in TOTALS}
        for draw in draws:
            totals = results[(tag, draw)]["totals"]
            row = []
            for name, key, _ in TOTALS:
                values = [totals[cell][key] if cell in totals else 0 for cell in CELLS]
                sums[name] = [total + value for total, value in zip(sums[name], values)]
                row.append(" / ".join(map(str, values)))
            print(f"| {build} | {draw.name()} | " + " | ".join(row) + " |")
        first = results[(tag, draws[0])]["totals"]
        of = [" of " + " / ".join(str(len(draws) * first[cell][of_key]) for cell in CELLS if cell in first)
              if of_key else "" for _, _, of_key in TOTALS]
        print(f"| {build} | sum | " + " | ".join(" / ".join(map(str, sums[name])) + tail
                                              for (name, _, _), tail in zip(TOTALS, of)) + " |")
    if a.against:
        print()
        for draw in draws:
            first, second = passing(results[("build", draw)]), passing(results[("against", draw)])
            print(f"{draw.name()}: found only with {a.build}: {sorted(first - second)}; only with {a.against}: {sorted(second - first)}")

if __name__ == "__main__":
    main()

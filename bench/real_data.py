#!/usr/bin/python3
"""eRMSM on the real scans of ../shared/data (recorded by others, no plane ground truth):
what a map and its planes look like outside the simulator.

    /usr/bin/python3 bench/real_data.py [--build build] [--data ../shared/data] [--out out/real]

For every data set and cell size: build the block layer (`--no-octree`; the 3DTK scans
registered with `--register` from their own start poses), detect planes, and print the
blocks and how many of them are vertical, the patches, their surface by class
and the detection time (2 threads). Data sets that are not there are skipped with a message.
"""
import argparse, bz2, collections, json, os, subprocess

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def run(cmd):
    return subprocess.run(cmd, check=True, capture_output=True, text=True)


def data_sets(data, out):
    """(name, scans, build options, what it is) for the data sets present."""
    sets = []
    threedtk = os.path.join(data, "3dtk_dat_3scans")
    if os.path.isdir(threedtk):
        scans = [os.path.join(threedtk, f"scan00{k}.3d") for k in range(3)]
        sets.append(("3dtk", scans, ["--register"], "3DTK's example: 3 scans of 81,360 points each, registered from their start poses"))
    octomap = os.path.join(data, "octomap_share_samples", "scan.dat.bz2")
    if os.path.exists(octomap):
        xyz = os.path.join(out, "fr079_scan.xyz")
        if not os.path.exists(xyz):
            with bz2.open(octomap, "rt") as packed, open(xyz + ".part", "w") as unpacked:
                unpacked.write(packed.read())
            os.replace(xyz + ".part", xyz)
        sets.append(("fr079", [xyz], ["--identity"], "OctoMap's scan.dat: one 3D scan of 88,206 points over 27 x 32 x 11 m"))
    bobkov = os.path.join(data, "bobkov_office_labels", "room2_gt_fine.pcd")
    if os.path.exists(bobkov):
        sets.append(("office", [bobkov], [], "Bobkov et al. room 2: a registered mobile-scanner cloud of 123,692 points, z 1.5-3.4 m"))
    return sets


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--data", default=os.path.join(os.path.dirname(ROOT), "shared", "data"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "real"))
    ap.add_argument("--cells", default="0.05,0.1")
    a = ap.parse_args()
    if not os.path.isdir(a.data):
        print(f"real_data: skipped, no data directory at {a.data}")
        return
    os.makedirs(a.out, exist_ok=True)
    mlmap = os.path.join(a.build, "mlmap")
    if not os.access(mlmap, os.X_OK):
        raise SystemExit(f"real_data: no mlmap CLI at {mlmap} (build it first, or give --build)")
    sets = data_sets(a.data, a.out)
    if not sets:
        print(f"real_data: skipped, none of the data sets is in {a.data}")
        return
    print("| data | cell m | blocks | vertical | patches | m² by class | detect s |")
    print("|---|---|---|---|---|---|---|")
    for name, scans, options, _ in sets:
        for cell in (float(c) for c in a.cells.split(",")):
            tag = f"{name}-{cell:g}"
            map_file, planes_file = os.path.join(a.out, tag + ".mlmap"), os.path.join(a.out, tag + ".planes.json")
            run([mlmap, "-q", "build", "-o", map_file, "--cell-size", str(cell), "--no-octree"] + options + scans)
            run([mlmap, "-q", "planes", map_file, "--threads", "2", "--json", planes_file])
            planes = json.load(open(planes_file))
            counts = json.loads(run([mlmap, "info", "--json", map_file]).stdout)["blocks"]
            blocks, vertical = counts["total"], counts["vertical"]
            area = collections.defaultdict(float)
            for plane in planes["planes"]:
                area[plane["label"]] += plane["area"]
            by_class = ", ".join(f"{label} {value:.1f}" for label, value in sorted(area.items(), key=lambda item: -item[1]))
            print(f"| {name} | {cell:g} | {blocks} | "
                  f"{100.0 * vertical / max(blocks, 1):.1f} % | {len(planes['planes'])} | {by_class} | "
                  f"{planes['timings']['total_s']:.3f} |")
    print()
    for name, _, _, what in sets:
        print(f"{name}: {what}")


if __name__ == "__main__":
    main()

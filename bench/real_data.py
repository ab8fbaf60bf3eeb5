#!/usr/bin/python3
"""Plane detection on the real scans of ../shared/data, scored against surfaces marked by hand.

    /usr/bin/python3 bench/real_data.py [--build build] [--data ../shared/data] [--out out/real]
        [--cells 0.05,0.1] [--peers /work/build-peers] [--only NAME,...] [--docs docs]
        [--turn DEG --shift X,Y] [--keep SHARE [--keep-seed N]]

Every scene of bench/real_clouds.py (3DTK's three scans, OctoMap's scan.dat, Bobkov's room 2,
PCL's office1 and two room scans, plane_seg's two stair scans) has an annotation file
bench/annotations/NAME.json: the floor, ceiling, walls, table tops, stair treads and risers a
person sees there, each a region and the plane it lies on (bench/real_annotations.py; made by
looking at views of the points and fitting planes in chosen regions, never from mlmap's output).

Per scene and cell size mlmap builds the block layer (--no-octree; 3DTK's scans registered
first with `mlmap register` from their .pose files), detects planes (2 threads) and labels every
input point (`mlmap label`, input order). Per marked surface the table gives
  share   the share of its points on its largest patch,
  n10     the patches that hold >= 10 % of its points,
  joins   the other marked surfaces with >= 10 % of their points on that same patch,
  rms     the RMS of its points to that patch's plane (`mlmap label --json`: the plane refitted to the
          points labelled with it; the planes JSON of `mlmap planes` where label has no --json) / to
          their own least-squares plane, cm;
and per scene the points on patches outside every marked surface ("unmarked") and the found surfaces
whose patch's class (planes JSON `label`) is not the kind marked; at the end, over
all scans, the surfaces found (and issue 19's split: walls, floor, ceiling >= 90 %, the others
>= 70 %, RMS to the patch's plane within 0.5 cm of the points' own fit) and the patches on no
marked surface per method. With --peers,
CGAL's efficient RANSAC (--eps 0.03 --angle 20 --min-support 500, as bench/planes_bench.py)
runs on the same points (annotation frame) and is scored the same way. Times: mlmap's
detection (planes JSON total_s) and build, CGAL's normals + detection.

Where the data's authors labelled the points themselves (Bobkov's room 2: object parts and
objects), the labels are scored too, with ../shared/peers/score.py (IoU >= 0.5), for mlmap at
each cell size and CGAL.

--turn and --shift place the scenes on the cell grid otherwise than their authors' frames do
(turned about the up axis, moved across by a fraction of a cell); bench/real_seeds.py --placements
runs twelve such placements, since every constant was tried on the authors' frames.

--keep thins every scan to that share of its points, drawn at random (seeded by --keep-seed)
before mlmap or CGAL sees them: the same surfaces seen with fewer points (a slower or coarser
scanner; along each scan line, since whole lines are not dropped). The marked surfaces are the
same; the authors' own labels (Bobkov's room 2) are not scored on a thinned cloud.
bench/real_seeds.py --densities runs 1, 0.5 and 0.25 over three thinning draws.

y-up scans (office1) are passed with `--up y` when `mlmap build --help` lists it, otherwise as
z-up scans (the benchmark turns them itself). Scans go to mlmap as .xyz files in their sensor
frame with a TUM pose file where the sensor position is known (so that `label` knows the
beams' origins), as world points otherwise. Missing data, annotations or peers are skipped
with a message. Writes out/real/NAME/*, out/real/real_data.md, out/real/real_data.json (the
totals per method and each marked surface's found / not found, for bench/real_seeds.py) and,
with --docs, one small picture per scene (docs/real-NAME.png).
"""
import argparse, json, math, os, re, subprocess, sys, time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import real_annotations  # noqa: E402
import real_clouds  # noqa: E402

CGAL_ARGS = ["--eps", "0.03", "--angle", "20", "--min-support", "500", "--max-planes", "60"]


def run(cmd):
    started = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({done.returncode}):\n{done.stderr.strip()}")
    return done, time.perf_counter() - started


def options_of(mlmap, command):
    """The long options `mlmap COMMAND --help` lists."""
    text = subprocess.run([mlmap, command, "--help"], capture_output=True, text=True).stdout
    return set(re.findall(r"(--[a-z][a-z-]*)", text))


def quaternion(r):
    """(qx, qy, qz, qw) of a rotation matrix."""
    w = math.sqrt(max(0.0, 1.0 + r[0, 0] + r[1, 1] + r[2, 2])) / 2
    x = math.copysign(math.sqrt(max(0.0, 1.0 + r[0, 0] - r[1, 1] - r[2, 2])) / 2, r[2, 1] - r[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1.0 - r[0, 0] + r[1, 1] - r[2, 2])) / 2, r[0, 2] - r[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1.0 - r[0, 0] - r[1, 1] + r[2, 2])) / 2, r[1, 0] - r[0, 1])
    return x, y, z, w


def yaw_about(up, degrees):
    """The turn by `degrees` about a scene's up axis ("z" or "y"), in the scene's own frame."""
    return real_clouds._rotation({"z": 2, "y": 1}[up], degrees)


def write_inputs(scene, folder, up_option, yaw=0.0, shift=(0.0, 0.0)):
    """The .xyz files and pose file (or None) mlmap is given, and the options it needs for the up axis.

    `yaw` (deg) turns the whole scene about its up axis and `shift` (m) moves it across (in the
    z-up frame) before mlmap sees it: every point keeps its line, so the marked surfaces (found in
    the annotation frame) still apply."""
    turn = np.eye(3)
    options = []
    if scene.up == "y":
        if up_option:
            options = ["--up", "y"]
        else:
            turn = real_clouds.Y_UP_TO_Z_UP
    # In the scene's own frame: a y-up scene's x and -z are z-up x and y.
    across = np.array([shift[0], shift[1], 0.0]) if scene.up == "z" else np.array([shift[0], 0.0, -shift[1]])
    move = turn @ across
    turn = turn @ yaw_about(scene.up, yaw)
    files, poses = [], []
    for k, (points, r, t) in enumerate(scene.scans):
        path = os.path.join(folder, f"scan{k:03d}.xyz")
        if scene.sensor_known:
            np.savetxt(path, points, fmt="%.5f")
            qx, qy, qz, qw = quaternion(turn @ r)
            tt = turn @ t + move
            poses.append(f"{k} {tt[0]:.6f} {tt[1]:.6f} {tt[2]:.6f} {qx:.9f} {qy:.9f} {qz:.9f} {qw:.9f}")
        else:
            np.savetxt(path, (points @ r.T + t) @ turn.T + move, fmt="%.5f")
        files.append(path)
    pose_file = None
    if poses:
        pose_file = os.path.join(folder, "poses.tum")
        open(pose_file, "w").write("\n".join(poses) + "\n")
    return files, pose_file, options


def score(labels, owner, points, planes, annotation, classes=None):
    """Per surface (share, n10, rms to the largest patch's plane, own rms, points, that patch's
    class) and the unmarked points.

    labels: per point the patch id (<0 none); planes: id -> (normal, offset) in the frame of `points`;
    classes: id -> class name (mlmap's planes JSON `label`), None for a method without classes.
    """
    rows = []
    for k, surface in enumerate(annotation["surfaces"]):
        mine = owner == k
        count = int(mine.sum())
        normal, d = real_annotations.fit_plane(points[mine], trim=0) if count >= 3 else (np.zeros(3), 0.0)
        own = real_annotations.rms_to_plane(points[mine], normal, d)
        ids, counts = np.unique(labels[mine & (labels >= 0)], return_counts=True)
        if count == 0 or len(ids) == 0:
            rows.append(dict(share=0.0, n10=0, joined=0, rms=float("nan"), own=own, points=count, cls=None))
            continue
        best = ids[np.argmax(counts)]
        n, off = planes[best]
        # Other marked surfaces with >= 10 % of their points on this patch: surfaces it joins.
        joined = sum(1 for j in range(len(annotation["surfaces"])) if j != k and
                     np.sum((owner == j) & (labels == best)) >= 0.1 * max(np.sum(owner == j), 1))
        rows.append(dict(share=counts.max() / count, n10=int((counts >= 0.1 * count).sum()), joined=joined,
                         rms=real_annotations.rms_to_plane(points[mine], n, off), own=own, points=count,
                         cls=classes.get(best) if classes is not None else None))
    on_patch = labels >= 0
    unmarked = on_patch & (owner < 0)
    # A patch lies on no marked surface when most of its points are outside every one.
    stray = [p for p in np.unique(labels[on_patch]) if np.mean(owner[labels == p] < 0) > 0.5]
    # Of those, the ones that are no flat surface (issue 19: "points on unmarked patches that
    # are not flat surfaces: none"): their points' RMS to the patch's plane more than twice
    # the median own-fit RMS of the scan's marked surfaces (its flat surfaces' roughness).
    own_rms = [row["own"] for row in rows if row["points"] >= 3 and not math.isnan(row["own"])]
    flat_rms = float(np.median(own_rms)) if own_rms else float("inf")
    rough = [p for p in stray if p in planes and
             real_annotations.rms_to_plane(points[labels == p], *planes[p]) > 2.0 * flat_rms]
    return rows, dict(on_patch=int(on_patch.sum()), unmarked=int(unmarked.sum()), patches=len(np.unique(labels[on_patch])),
                      stray_patches=len(stray), stray_points=int(np.isin(labels, stray).sum()), rough_strays=len(rough))


def thin(scene, keep, seed):
    """Keeps a share `keep` of each scan's points, drawn at random (the same draw for a seed)."""
    draw = np.random.default_rng(seed)
    scene.scans = [(points[draw.random(len(points)) < keep], r, t) for points, r, t in scene.scans]


def posed_options(pose_file, features):
    """World-frame clouds (no sensor pose) are mapped as they are: --identity where the CLI asks for it."""
    return ["--poses", pose_file] if pose_file else (["--identity"] if "--identity" in features["build"] else [])


def build_map(mlmap, folder, cell, files, pose_file, up_options, features):
    """The block layer of the scene at this cell size (FOLDER/cellC.mlmap); returns (path, build seconds)."""
    tag = os.path.join(folder, f"cell{cell:g}")
    # The benchmark drops a scanner's own and no-return readings itself (real_clouds.py),
    # so mlmap's range limits are opened wide.
    wide = (["--max-range", "1e9"] if "--max-range" in features["build"] else []) + \
           (["--min-range", "0"] if "--min-range" in features["build"] else [])
    build = [mlmap, "-q", "build", "-o", tag + ".mlmap", "--cell-size", str(cell), "--no-octree"] + \
        posed_options(pose_file, features) + up_options + wide
    _, build_s = run(build + files)
    return tag + ".mlmap", build_s


def scene_inputs(mlmap, scene, folder, features, yaw=0.0, shift=(0.0, 0.0)):
    """The scene's .xyz files, its pose file (registered first where the scene asks) and up options."""
    files, pose_file, up_options = write_inputs(scene, folder, "--up" in features["build"], yaw, shift)
    if scene.register:
        registered = os.path.join(folder, "registered.tum")
        run([mlmap, "-q", "register", "-o", registered, "--poses", pose_file] + files)
        pose_file = registered
    return files, pose_file, up_options


def run_mlmap(mlmap, scene, folder, cell, files, pose_file, up_options, features, planes_args=()):
    tag = os.path.join(folder, f"cell{cell:g}")
    posed = posed_options(pose_file, features)
    _, build_s = build_map(mlmap, folder, cell, files, pose_file, up_options, features)
    run([mlmap, "-q", "planes", tag + ".mlmap", "--threads", "2", "-o", tag + ".planes.mlmap", "--json", tag + ".planes.json"] + list(planes_args))
    planes_json = json.load(open(tag + ".planes.json"))
    label = [mlmap, "-q", "label", tag + ".planes.mlmap", "-o", tag + ".labels.xyz"] + posed
    if "--up" in features["label"]:
        label += up_options  # so that label places the points in the frame of the map's planes
    if "--max-range" in features["label"]:
        label += ["--max-range", "1e9"]  # every input point keeps its line: labels come in input order
    if "--min-range" in features["label"]:
        label += ["--min-range", "0"]
    if "--json" in features["label"]:
        label += ["--json", tag + ".label-planes.json"]  # the planes refitted to their labelled points
    run(label + files)
    table = np.loadtxt(tag + ".labels.xyz", dtype=np.float64, ndmin=2)
    fitted = json.load(open(tag + ".label-planes.json")) if "--json" in features["label"] else planes_json
    planes = {p["id"]: (np.array(p["normal"]), p["offset"]) for p in fitted["planes"]}
    classes = {p["id"]: p.get("label") for p in planes_json["planes"]}
    return table[:, :3], table[:, 3].astype(int), planes, classes, dict(build_s=build_s, detect_s=planes_json["timings"]["total_s"])


def run_cgal(peers, folder, points):
    program = os.path.join(peers, "cgal_ransac")
    cloud = os.path.join(folder, "world.xyz")
    np.savetxt(cloud, points, fmt="%.5f")
    done, _ = run([program, cloud, "--labels", os.path.join(folder, "cgal.labels")] + CGAL_ARGS)
    result = json.loads(done.stdout)
    labels = np.loadtxt(os.path.join(folder, "cgal.labels"), dtype=int)
    planes = {k: (np.array(p["normal"]), p["d"]) for k, p in enumerate(result["planes"])}
    seconds = result["seconds"]
    return labels, planes, dict(detect_s=seconds.get("normals", 0.0) + seconds["detect"])


def cell_text(row):
    if row is None:
        return "- | - | - | -"
    # The largest patch's plane says nothing about a surface it barely touches.
    rms = "-" if math.isnan(row["rms"]) or row["n10"] == 0 else f"{100 * row['rms']:.1f}/{100 * row['own']:.1f}"
    return f"{100 * row['share']:.0f} | {row['n10']} | {row['joined']} | {rms}"


def table(scene, annotation, results):
    """Markdown: one line per marked surface, columns per method; then unmarked points and times."""
    methods = list(results)
    head = "| surface | kind | points | " + " | ".join(f"{m} share % | n10 | joins | rms cm" for m in methods) + " |"
    lines = [f"#### {scene.name}: {scene.title}", "", head, "|" + "---|" * (3 + 4 * len(methods))]
    for k, surface in enumerate(annotation["surfaces"]):
        points = next(iter(results.values()))["rows"][k]["points"]
        lines.append(f"| {surface['name']} | {surface['kind']} | {points} | " +
                     " | ".join(cell_text(results[m]["rows"][k]) for m in methods) + " |")
    lines.append("")
    lines.append("| | " + " | ".join(methods) + " |")
    lines.append("|---|" + "---|" * len(methods))
    lines.append("| surfaces found: >= 90 % (walls, floor, ceiling) or >= 70 % (the others) on a patch that joins no other | " + " | ".join(
        f"{passed(annotation, results[m]['rows'])}" for m in methods) + " |")
    lines.append("| patches / on no marked surface / of those not flat (RMS > 2x the marked surfaces' median) | " + " | ".join(
        f"{results[m]['extra']['patches']} / {results[m]['extra']['stray_patches']} / {results[m]['extra']['rough_strays']}"
        for m in methods) + " |")
    lines.append("| points on patches / outside marked surfaces | " + " | ".join(
        f"{results[m]['extra']['on_patch']} / {results[m]['extra']['unmarked']}" for m in methods) + " |")
    lines.append("| detection s (mlmap: planes, 2 threads; CGAL: normals + RANSAC) | " + " | ".join(
        f"{results[m]['times']['detect_s']:.2f}" for m in methods) + " |")
    lines.append("| map build s (mlmap build --no-octree) | " + " | ".join(
        f"{results[m]['times']['build_s']:.2f}" if "build_s" in results[m]["times"] else "-" for m in methods) + " |")
    return "\n".join(lines) + "\n"




def issue_counts(annotation, rows):
    """Issue 19's figures for one scene: walls, floor and ceiling found (>= 90 %), the other
    surfaces found (>= 70 %), each with how many are marked, and the surfaces whose points lie
    within 0.5 cm (RMS) of the largest patch's plane as of their own least-squares fit."""
    counts = dict(structural_found=0, structural=0, other_found=0, other=0, rms_ok=0, class_ok=0, classed=0)
    for surface, row in zip(annotation["surfaces"], rows):
        key = "structural" if is_structural(surface) else "other"
        counts[key] += 1
        counts[key + "_found"] += int(is_found(surface, row))
        right = class_right(surface, row)
        if right is not None:
            counts["classed"] += 1
            counts["class_ok"] += int(right)
        counts["rms_ok"] += int(row["n10"] > 0 and not math.isnan(row["rms"]) and row["rms"] - row["own"] <= 0.005)
    return counts


# mlmap's class (planes JSON `label`) for each marked kind: treads and risers are steps' parts.
CLASS_OF_KIND = dict(floor="floor", ceiling="ceiling", wall="wall", table="table", tread="step", riser="step",
                     step="step")


def class_right(surface, row):
    """The class a user reads off a found surface's patch, against the kind marked: True or
    False, None where the surface was not found, its patch has no class or its kind none."""
    wanted = CLASS_OF_KIND.get(surface["kind"])
    if not (wanted and is_found(surface, row) and row.get("cls") is not None):
        return None
    return row["cls"] == wanted


def class_misses(annotation, results):
    """Per method, the found surfaces whose patch's class is not the kind marked: 'NAME (method): class'."""
    misses = []
    for method, result in results.items():
        for surface, row in zip(annotation["surfaces"], result["rows"]):
            if class_right(surface, row) is False:
                misses.append(f"{surface['name']} ({method}): {row['cls']}")
    return misses


def is_structural(surface):
    return surface["kind"] in ("floor", "ceiling", "wall")


def is_found(surface, row):
    """>= 90 % (walls, floor, ceiling) or >= 70 % (the others) of the surface on one patch that joins no other."""
    return row["share"] >= (0.9 if is_structural(surface) else 0.7) and row["joined"] == 0


def found_count(annotation, rows):
    """(surfaces found, surfaces marked): >= 90 % (walls, floor, ceiling) or >= 70 % on a patch joining no other."""
    counts = issue_counts(annotation, rows)
    return counts["structural_found"] + counts["other_found"], len(rows)


def passed(annotation, rows):
    good, total = found_count(annotation, rows)
    return f"{good} of {total}"


def totals_table(totals):
    """Markdown: per method, over every scene scored, the surfaces found and the patches on no marked surface."""
    lines = ["#### all scans", "", "| | " + " | ".join(totals) + " |", "|---|" + "---|" * len(totals),
             "| surfaces found | " + " | ".join(f"{t['found']} of {t['marked']}" for t in totals.values()) + " |",
             "| walls, floor, ceiling: >= 90 % on a patch joining no other | " + " | ".join(
                 f"{t['structural_found']} of {t['structural']}" for t in totals.values()) + " |",
             "| the others (tables, treads, steps): >= 70 % | " + " | ".join(
                 f"{t['other_found']} of {t['other']}" for t in totals.values()) + " |",
             "| RMS to the patch's plane within 0.5 cm of the points' own fit | " + " | ".join(
                 f"{t['rms_ok']} of {t['marked']}" for t in totals.values()) + " |",
             "| found surfaces whose patch's class is the kind marked (tread and riser: step) | " + " | ".join(
                 f"{t['class_ok']} of {t['classed']}" if t["classed"] else "-" for t in totals.values()) + " |",
             "| patches on no marked surface | " + " | ".join(str(t["stray"]) for t in totals.values()) + " |",
             "| of those not flat (points' RMS to the patch > 2x the scan's marked surfaces' median) | " + " | ".join(
                 str(t["rough"]) for t in totals.values()) + " |",
             "| detection s, sum | " + " | ".join(f"{t['detect_s']:.2f}" for t in totals.values()) + " |"]
    return "\n".join(lines) + "\n"


def picture(points, owner, labelled, out, title):
    """Top and side views of the marked surfaces and of each method's patches, cropped to the marked
    surfaces; a small palette PNG (the README shows one per scene)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    marked = points[owner >= 0]
    lo, hi = np.quantile(marked, 0.005, axis=0) - 0.3, np.quantile(marked, 0.995, axis=0) + 0.3
    inside = np.all((points >= lo) & (points <= hi), axis=1)
    pick = np.flatnonzero(inside)
    pick = pick[np.random.default_rng(1).permutation(len(pick))[:40000]]
    panels = [("marked surfaces", owner)] + list(labelled.items())
    fig, axes = plt.subplots(2, len(panels), figsize=(3.2 * len(panels), 5.2), squeeze=False,
                             gridspec_kw={"height_ratios": [max(hi[1] - lo[1], 0.5), max(hi[2] - lo[2], 0.5)]})
    colours = plt.get_cmap("tab20")
    for column, (name, ids) in enumerate(panels):
        ids = ids[pick]
        p = points[pick]
        for row, (i, j) in enumerate(((0, 1), (0, 2))):
            ax = axes[row, column]
            ax.scatter(p[ids < 0, i], p[ids < 0, j], s=0.3, c="0.82", linewidths=0)
            for k in np.unique(ids[ids >= 0]):
                ax.scatter(p[ids == k, i], p[ids == k, j], s=0.6, color=colours(k % 20), linewidths=0)
            ax.set_xlim(lo[i], hi[i]), ax.set_ylim(lo[j], hi[j]), ax.set_aspect("equal")
            ax.tick_params(labelsize=5)
            ax.set_title(f"{name}: {'top' if row == 0 else 'side'} ({'xyz'[i]}{'xyz'[j]})", fontsize=6)
    fig.suptitle(title, fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=72)
    plt.close(fig)
    try:  # a palette image is a third of the size
        from PIL import Image
        Image.open(out).convert("RGB").quantize(colors=48).save(out, optimize=True)
    except ImportError:
        pass


def scored_cells(scorer, truth_file, folder, labelled):
    """Each method's labels scored against TRUTH_FILE with ../shared/peers/score.py (IoU >= 0.5,
    true regions of >= 300 points, patches counted where they touch one): "method: matched of
    true, patches, F1" joined by "; "."""
    cells = []
    for method, labels in labelled.items():
        predicted = os.path.join(folder, "predicted.labels")
        np.savetxt(predicted, np.asarray(labels, dtype=int), fmt="%d")
        done, _ = run(["/usr/bin/python3", scorer, truth_file, predicted, "--min-gt-points", "300"])
        result = json.loads(done.stdout)
        cells.append(f"{method}: {result['matched']} of {result['gt_planes']}, {result['pred_planes']} patches, "
                     f"F1 {result['f1']:.2f}")
    return "; ".join(cells)


# Scenes whose own authors labelled their points (label 0: not labelled), scored beside the
# project's annotation with the peers' scorer (../shared/peers/score.py: patch precision,
# recall and F1 at point IoU >= 0.5, unlabelled points left out, only patches touching a
# labelled part of >= 300 points counted). Bobkov's labels are object parts (table tops,
# seats, backs, shelf boards) and whole objects, not planes: a part off its plane by 2-6 cm
# RMS (the data's README) is scored as one surface all the same.
AUTHORS_LABELS = {"bobkov_room2": [("parts", "bobkov_office_labels/room2_gt_fine.pcd"),
                                   ("objects", "bobkov_office_labels/room2_gt_coarse.pcd")]}


def authors_scores(data, name, folder, world, labelled, scorer):
    """Markdown lines: per label set and method, matched / labelled, patches counted, F1."""
    lines = []
    for kind, path in AUTHORS_LABELS.get(name, []):
        _, _, fields = real_clouds.read_pcd(os.path.join(data, path))
        truth = fields["label"][1:].astype(int)  # the scene drops the file's stray first point, as here
        if len(truth) != len(world):
            raise SystemExit(f"real_data: {name}: {path} has {len(truth)} labels for {len(world)} points")
        truth[truth == 0] = -1
        truth_file = os.path.join(folder, f"authors_{kind}.xyz")
        np.savetxt(truth_file, np.column_stack([world, truth]), fmt="%.5f %.5f %.5f %d")
        lines.append(f"- the authors' {kind} (>= 300 points): " + scored_cells(scorer, truth_file, folder, labelled))
    return lines


def marked_scores(name, folder, world, owner, labelled, scorer):
    """Markdown line: the marked surfaces scored as instances with ../shared/peers/score.py
    (patch precision, recall, F1 at point IoU >= 0.5; points on no marked surface left out, and
    surfaces of fewer than 300 points; a patch counts where it touches a kept surface). Unlike
    `share`, IoU also charges a patch for what it takes beyond its surface (a floor patch holding
    the seats)."""
    truth_file = os.path.join(folder, "marked.xyz")
    np.savetxt(truth_file, np.column_stack([world, owner]), fmt="%.5f %.5f %.5f %d")
    return "- the marked surfaces as instances (IoU >= 0.5, >= 300 points): " + scored_cells(scorer, truth_file, folder, labelled)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--data", default=os.path.join(os.path.dirname(ROOT), "shared", "data"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "real"))
    ap.add_argument("--cells", default="0.05,0.1")
    ap.add_argument("--peers", help="build directory of ../shared/peers (cgal_ransac); optional")
    ap.add_argument("--only", help="comma-separated scene names")
    ap.add_argument("--planes-args", default="", help="extra arguments for `mlmap planes`, e.g. \"--noise 0.01\"")
    ap.add_argument("--docs", help="write one picture per scene here (docs/real-NAME.png)")
    ap.add_argument("--turn", type=float, default=0.0,
                    help="turn every scene by this many degrees about its up axis (and --shift it) before mlmap "
                         "sees it: the buildings' walls then lie off the cell grid (CGAL, grid-free, is not rerun)")
    ap.add_argument("--shift", default="0,0", help="m, with --turn: the scene moved across by x,y (default 0,0)")
    ap.add_argument("--keep", type=float, default=1.0,
                    help="share of each scan's points kept, drawn at random (default 1: all): the scans thinned")
    ap.add_argument("--keep-seed", type=int, default=1, help="seed of --keep's draw (default 1)")
    a = ap.parse_args()
    try:
        shift = tuple(float(v) for v in a.shift.split(","))
    except ValueError:
        shift = ()
    if len(shift) != 2:
        raise SystemExit(f"real_data: --shift takes two numbers, x,y (got {a.shift!r})")
    if not 0.0 < a.keep <= 1.0:
        raise SystemExit(f"real_data: --keep takes a share in (0, 1] (got {a.keep})")
    if not os.path.isdir(a.data):
        print(f"real_data: skipped, no data directory at {a.data}")
        return
    if a.docs:
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            raise SystemExit("real_data: --docs draws with matplotlib: apt-get install python3-matplotlib")
    mlmap = os.path.join(a.build, "mlmap")
    if not os.access(mlmap, os.X_OK):
        raise SystemExit(f"real_data: no mlmap CLI at {mlmap} (build it first, or give --build)")
    cgal = a.peers and os.access(os.path.join(a.peers, "cgal_ransac"), os.X_OK)
    if a.peers and not cgal:
        print(f"real_data: no cgal_ransac in {a.peers}, CGAL skipped")
    features = {c: options_of(mlmap, c) for c in ("build", "label", "register")}
    cells = [float(c) for c in a.cells.split(",")]
    report, totals, verdicts = [], {}, []
    for name, scene, why in real_clouds.scenes(a.data):
        if a.only and name not in a.only.split(","):
            continue
        if scene is None:
            print(f"real_data: {name} skipped ({why})")
            continue
        if a.keep < 1.0:
            thin(scene, a.keep, a.keep_seed)
        annotation = real_annotations.load(name)
        if annotation is None:
            print(f"real_data: {name} skipped (no bench/annotations/{name}.json)")
            continue
        folder = os.path.join(a.out, name)
        os.makedirs(folder, exist_ok=True)
        world = scene.world()
        owner = real_annotations.memberships(world, annotation)
        files, pose_file, up_options = scene_inputs(mlmap, scene, folder, features, a.turn, shift)
        results, labelled = {}, {}
        for cell in cells:
            points, labels, planes, classes, times = run_mlmap(mlmap, scene, folder, cell, files, pose_file, up_options, features,
                                                      a.planes_args.split())
            if len(labels) != len(world):
                raise SystemExit(f"real_data: {name}: mlmap label wrote {len(labels)} points for {len(world)} input points")
            rows, extra = score(labels, owner, points, planes, annotation, classes)
            results[f"mlmap {cell:g}"] = dict(rows=rows, extra=extra, times=times)
            labelled[f"mlmap {cell:g} m"] = labels
        if cgal and a.turn == 0.0 and shift == (0.0, 0.0):
            labels, planes, times = run_cgal(a.peers, folder, world)
            rows, extra = score(labels, owner, world, planes, annotation)
            results["CGAL"] = dict(rows=rows, extra=extra, times=times)
            labelled["CGAL"] = labels
        text = table(scene, annotation, results)
        wrong = class_misses(annotation, results)
        if wrong:
            text += "\n- found, but another class: " + "; ".join(wrong) + "\n"
        for method, result in results.items():
            found, marked = found_count(annotation, result["rows"])
            total = totals.setdefault(method, dict(found=0, marked=0, stray=0, rough=0, detect_s=0.0, structural_found=0,
                                                   structural=0, other_found=0, other=0, rms_ok=0, class_ok=0,
                                                   classed=0))
            total["found"] += found
            total["marked"] += marked
            for key, count in issue_counts(annotation, result["rows"]).items():
                total[key] += count
            total["stray"] += result["extra"]["stray_patches"]
            total["rough"] += result["extra"]["rough_strays"]
            verdicts += [dict(scene=name, surface=surface["name"], method=method, found=bool(is_found(surface, row)))
                         for surface, row in zip(annotation["surfaces"], result["rows"])]
            total["detect_s"] += result["times"]["detect_s"]
        scorer = os.path.join(os.path.dirname(a.data), "peers", "score.py")
        if os.path.exists(scorer):
            text += "\n" + marked_scores(name, folder, world, owner, labelled, scorer) + "\n"
        if name in AUTHORS_LABELS and os.path.exists(scorer) and a.keep == 1.0:
            text += "\nScored on the labels the data's authors made (`../shared/peers/score.py`):\n\n"
            text += "\n".join(authors_scores(a.data, name, folder, world, labelled, scorer)) + "\n"
        print(text, flush=True)
        report.append(text)
        if a.docs:
            os.makedirs(a.docs, exist_ok=True)
            picture(world, owner, labelled, os.path.join(a.docs, f"real-{name}.png"),
                    f"{name}: {scene.title}; grey: no surface / no patch")
    if totals:
        text = totals_table(totals)
        print(text, flush=True)
        report.append(text)
    if report:
        os.makedirs(a.out, exist_ok=True)
        commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
        head = (f"`{' '.join(['bench/real_data.py'] + sys.argv[1:])}` at {commit or '?'}, "
                f"{time.strftime('%Y-%m-%d %H:%M')}, load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores\n")
        print(head)
        open(os.path.join(a.out, "real_data.md"), "w").write(head + "\n" + "\n".join(report))
        json.dump(dict(totals=totals, surfaces=verdicts), open(os.path.join(a.out, "real_data.json"), "w"), indent=1)


if __name__ == "__main__":
    main()

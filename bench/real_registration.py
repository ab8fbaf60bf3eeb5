#!/usr/bin/env python3
"""Registration on the real scans of ../shared/data, side by side with Open3D and PCL (issue 20).

No ground truth exists for these scans, so the figures are agreement and residuals:

- PCL's room scans (one room from two places): room_scan2 onto room_scan1 from the odometry
  start PCL's NDT tutorial gives (yaw 0.6931 rad, t = (1.79387, 0.720047, 0)), and the
  transform the data's README found by its own point-to-plane ICP (not ground truth either);
- 3DTK's three scans, started from their .pose files (odometry): pairs 0-1 and 1-2.

mlmap is `mlmap register --report` (scan-to-map, its verification and retries, then the pose
graph); Open3D and PCL are the peers' point-to-plane ICP at their defaults (0.05 m voxels,
gates 0.5 then 0.1 m), pairwise from the same starts. Per pair it prints each method's
relative pose, the translation and rotation between each two methods' results, mlmap's
verdict (verified, explained share, residual spread against the expected one, and apart for
walls and for floors and ceilings) and the
seconds (mlmap: the whole register command, reading included; the peers: their own total,
reading excluded). Skips with a message where ../shared/data or the peers are absent.

    /usr/bin/python3 bench/real_registration.py [--build build] [--peers /work/build-peers]
        [--data ../shared/data] [--out out/real_registration]
"""
import argparse, json, math, os, subprocess, sys, time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import real_clouds  # noqa: E402
from icp_stress import errors, read_tum  # noqa: E402
from merge_register import write_tum  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

# PCL's NDT tutorial (doc/tutorials/content/normal_distributions_transform.rst): "initial
# alignment estimate found using robot odometry", room_scan2 -> room_scan1.
NDT_START_YAW_RAD, NDT_START_T = 0.6931, (1.79387, 0.720047, 0.0)
# ../shared/data/pcl_room_scans/README.md: its authors' point-to-plane ICP from that start.
README_TRANSFORM = np.array([[0.75637, -0.65378, 0.02168, 1.97081],
                             [0.65362, 0.75668, 0.01467, 0.05699],
                             [-0.02599, 0.00308, 0.99966, 0.02532],
                             [0.0, 0.0, 0.0, 1.0]])


def pose_matrix(r, t):
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = r, t
    return m


def describe(m):
    yaw = math.degrees(math.atan2(m[1, 0], m[0, 0]))
    return f"t ({m[0, 3]:.3f}, {m[1, 3]:.3f}, {m[2, 3]:.3f}) m, yaw {yaw:.2f}°"


def residual_judge(source_path, target_path):
    """A referee independent of every method: for a relative pose, the share of (a sample of)
    the source's points within 5 cm of the target's points, and the robust spread (MAD as σ)
    of their distances to the target's local plane (20 neighbours) where it is flat. None
    without scipy."""
    try:
        from scipy.spatial import cKDTree
    except ImportError:
        return None
    source = np.loadtxt(source_path, ndmin=2)
    target = np.loadtxt(target_path, ndmin=2)
    source = source[np.random.default_rng(1).permutation(len(source))[:20000]]
    tree = cKDTree(target)

    def judge(m):
        moved = source @ m[:3, :3].T + m[:3, 3]
        distance, nearest = tree.query(moved)
        close = distance < 0.2
        _, neighbours = tree.query(target[nearest[close]], k=20)
        patch = target[neighbours] - target[neighbours].mean(axis=1, keepdims=True)
        values, vectors = np.linalg.eigh(np.einsum("nki,nkj->nij", patch, patch))
        flat = values[:, 0] / values.sum(axis=1) < 0.02
        normal = vectors[:, :, 0]
        residual = np.abs(np.einsum("ni,ni->n", normal, moved[close] - target[nearest[close]]))[flat]
        return (distance < 0.05).mean(), 1.4826 * np.median(residual) if len(residual) else float("nan")

    return judge


def kinds(scan):
    """'; walls X, floors and ceilings Y' (cm) from a register report's per-kind figures, where present."""
    level, upright = scan.get("level_surfaces"), scan.get("upright_surfaces")
    if not level or not upright or not level["matched"] or not upright["matched"]:
        return ""
    return (f"; walls {100 * upright['residual_spread_m']:.2f}, "
            f"floors and ceilings {100 * level['residual_spread_m']:.2f}")


def run_peer(binary, source, target, poses, i, j):
    done = subprocess.run([binary, source, target, "--poses", poses, "--source-index", str(i), "--target-index", str(j)],
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{binary} failed: {done.stderr.strip()}")
    out = json.loads(done.stdout)
    return np.array(out["relative_pose"]["matrix"]), out["seconds"]["total"], out.get("fitness")


def cases(data, out):
    """(name, (mlmap's files, the peers' .xyz files), start poses, pairs, references) per scan set present."""
    found = []
    scenes = {name: scene for name, scene, _ in real_clouds.scenes(data)}
    rooms = [scenes.get("room_scan1"), scenes.get("room_scan2")]
    if all(rooms):
        files = []
        for k, scene in enumerate(rooms):
            path = os.path.join(out, f"room_scan{k + 1}.xyz")
            np.savetxt(path, scene.scans[0][0], fmt="%.5f")
            files.append(path)
        c, s = math.cos(NDT_START_YAW_RAD), math.sin(NDT_START_YAW_RAD)
        start = pose_matrix(np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), NDT_START_T)
        # mlmap reads the PCD files as a user would (each scan line stored twice); the peers
        # read .xyz, here without the duplicates.
        pcds = [os.path.join(data, "pcl_room_scans", f"room_scan{k}.pcd") for k in (1, 2)]
        found.append(("PCL room scans (2 onto 1, PCL's odometry start)", (pcds, files), [np.eye(4), start], [(0, 1)],
                      {(0, 1): ("the data README's ICP", README_TRANSFORM)}))
    else:
        print("skipping PCL's room scans: not in", data)
    tdtk = scenes.get("3dtk")
    if tdtk:
        files, starts = [], []
        for k, (points, r, t) in enumerate(tdtk.scans):
            path = os.path.join(out, f"3dtk_scan{k:03d}.xyz")
            np.savetxt(path, points, fmt="%.5f")
            files.append(path)
            starts.append(pose_matrix(r, t))
        found.append(("3DTK's three scans (their .pose starts)", (files, files), starts, [(0, 1), (1, 2)], {}))
    else:
        print("skipping 3DTK's scans: not in", data)
    return found


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--peers", default="/work/build-peers")
    ap.add_argument("--data", default=os.path.join(ROOT, "..", "shared", "data"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "real_registration"))
    a = ap.parse_args()
    if not os.path.isdir(a.data):
        print(f"skipping: no real scans at {a.data} (../shared is not beside this clone)")
        return 0
    mlmap = os.path.join(a.build, "mlmap")
    peers = {name: os.path.join(a.peers, name) for name in ("open3d_icp", "pcl_icp")}
    peers = {name: path for name, path in peers.items() if os.path.exists(path)}
    if not peers:
        print(f"(no ICP peers in {a.peers}: mlmap alone)")
    os.makedirs(a.out, exist_ok=True)
    load = os.getloadavg()[0]
    print(f"`bench/real_registration.py` {time.strftime('%Y-%m-%d %H:%M')}, load average {load:.1f} on {os.cpu_count()} cores\n")
    for name, (mlmap_files, files), starts, pairs, references in cases(a.data, a.out):
        tag = os.path.join(a.out, name.split()[0].lower())
        write_tum(tag + "_start.tum", starts)
        began = time.perf_counter()
        done = subprocess.run([mlmap, "-q", "register", "-o", tag + "_mlmap.tum", "--poses", tag + "_start.tum",
                               "--report", tag + "_report.json"] + mlmap_files, capture_output=True, text=True)
        seconds = time.perf_counter() - began
        if done.returncode != 0:
            raise RuntimeError(f"mlmap register failed: {done.stderr.strip()}")
        registered = read_tum(tag + "_mlmap.tum")
        report = json.load(open(tag + "_report.json"))["scans"]
        print(f"#### {name}\n")
        print(f"mlmap register: {seconds:.2f} s for {len(files)} scans (reading included)\n")
        for i, j in pairs:
            print("| pair | method | relative pose | s | verdict |")
            print("|---|---|---|---|---|")
            results = {"mlmap": np.linalg.inv(registered[i]) @ registered[j]}
            scan = report[j]
            verdict = ("verified" if scan["verified"] else "NOT verified") + \
                f": {100 * scan['explained_share']:.0f} % explained, residual spread " \
                f"{100 * scan['residual_spread_m']:.2f} cm (expected {100 * scan['expected_residual_m']:.2f}" + \
                kinds(scan) + f"), {scan['icp_runs']} ICP runs"
            start = np.linalg.inv(starts[i]) @ starts[j]
            print(f"| {i}-{j} | start | {describe(start)} | | |")
            print(f"| {i}-{j} | mlmap (scan-to-map, pose graph) | {describe(results['mlmap'])} | | {verdict} |")
            for peer, binary in peers.items():
                matrix, peer_s, fitness = run_peer(binary, files[j], files[i], tag + "_start.tum", j, i)
                results[peer] = matrix
                print(f"| {i}-{j} | {peer} | {describe(matrix)} | {peer_s:.2f} | fitness {fitness:.2f} |")
            for label, matrix in [references[(i, j)]] if (i, j) in references else []:
                results[label] = matrix
                print(f"| {i}-{j} | {label} | {describe(matrix)} | | |")
            judge = residual_judge(files[j], files[i])
            if judge:
                verdicts = []
                for label, matrix in [("start", start)] + list(results.items()):
                    within, spread = judge(matrix)
                    verdicts.append(f"{label} {100 * within:.0f} % / {100 * spread:.2f} cm")
                print(f"\n- pair {i}-{j}, residuals (source points within 5 cm of the target / robust spread "
                      "about its flat local planes): " + "; ".join(verdicts))
            names = list(results)
            agreement = []
            for x in range(len(names)):
                for y in range(x + 1, len(names)):
                    cm, deg = errors(results[names[x]], results[names[y]])
                    agreement.append(f"{names[x]} / {names[y]} {cm:.1f} cm, {deg:.2f}°")
            print(f"- pair {i}-{j}, between the results: " + "; ".join(agreement) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The hand-made surface annotations of the real scans (bench/annotations/NAME.json) and the tools
used to make and check them.

An annotation file lists the surfaces a person sees in one scene, in the frame of
bench/real_clouds.py (the data's own poses, z up):

    {"scene": "room_scan1", "frame": "...", "notes": "...",
     "surfaces": [{"name": "floor", "kind": "floor",
                   "region": {"box": [[x0, y0, z0], [x1, y1, z1]]}      (or "polygon": [[x, y], ...], "z": [z0, z1]),
                   "exclude": [{"box": ...}, ...]                          (optional: holes in the region),
                   "plane": [nx, ny, nz, d],  "tolerance": 0.05}]}

A point belongs to a surface when it lies in the region, in none of its exclusions, and within
the tolerance of the plane (n·p + d = 0). Kinds: floor, ceiling, wall, table (desk/table/sideboard
tops), tread, riser, step (tilted block faces), other.

The planes were fitted with numpy (fit_plane below) to the points of regions chosen by looking at
top and side views and slices (views below); nothing here reads mlmap's output.

    /usr/bin/python3 bench/real_annotations.py views NAME [--z0 Z --z1 Z] [--box x0,y0,z0,x1,y1,z1]
    /usr/bin/python3 bench/real_annotations.py fit NAME x0,y0,z0,x1,y1,z1
    /usr/bin/python3 bench/real_annotations.py check NAME

`check` also refits each marked plane on the points within its tolerance until they stay the same
(settled_plane) and says where that moves it by more than 0.5 deg: such a marking mixes two
surfaces, or the surface is not flat (fr079's step bands, a sparse far wall); and it says where a
plane within 15 deg of the marking holds over 10 % more of the region's points within half the
tolerance (best_plane_in_region): a marking settled on a compromise between two faces. Look at
either in a side view before changing it.
"""
import argparse, json, math, os, sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
ANNOTATIONS = os.path.join(HERE, "annotations")
KINDS = ("floor", "ceiling", "wall", "table", "tread", "riser", "step", "other")


def _in_region(points, region):
    if "box" in region:
        lo, hi = np.array(region["box"][0]), np.array(region["box"][1])
        return np.all((points >= lo) & (points <= hi), axis=1)
    z0, z1 = region["z"]
    return _in_polygon(points[:, :2], np.array(region["polygon"], dtype=float)) & \
        (points[:, 2] >= z0) & (points[:, 2] <= z1)


def _in_polygon(xy, polygon):
    """Even-odd rule: a point is inside when a ray towards +x crosses the outline an odd number of
    times (numpy only, so scoring needs no plotting library)."""
    inside = np.zeros(len(xy), dtype=bool)
    x, y = xy[:, 0], xy[:, 1]
    for (xa, ya), (xb, yb) in zip(polygon, np.roll(polygon, -1, axis=0)):
        straddles = (ya > y) != (yb > y)
        if not straddles.any():
            continue
        with np.errstate(divide="ignore", invalid="ignore"):
            crossing_x = xa + (y - ya) * (xb - xa) / (yb - ya)
        inside ^= straddles & (x < crossing_x)
    return inside


def _in_marked_region(points, surface):
    """Points in a surface's region and out of its exclusions (whatever their distance from its plane)."""
    mask = _in_region(points, surface["region"])
    for hole in surface.get("exclude", []):
        mask &= ~_in_region(points, hole)
    return mask


def surface_mask(points, surface):
    """Points of one annotated surface: in its region, out of its exclusions, near its plane."""
    plane = np.array(surface["plane"])
    return _in_marked_region(points, surface) & (np.abs(points @ plane[:3] + plane[3]) <= surface["tolerance"])


def load(name):
    path = os.path.join(ANNOTATIONS, name + ".json")
    if not os.path.exists(path):
        return None
    annotation = json.load(open(path))
    for surface in annotation["surfaces"]:
        if surface["kind"] not in KINDS:
            raise ValueError(f"{path}: surface {surface['name']}: kind {surface['kind']} is not one of {KINDS}")
    return annotation


def memberships(points, annotation):
    """Per point the index of its surface (-1 none); a point in two surfaces goes to the nearer plane."""
    owner, distance = np.full(len(points), -1), np.full(len(points), np.inf)
    for k, surface in enumerate(annotation["surfaces"]):
        plane = np.array(surface["plane"])
        d = np.abs(points @ plane[:3] + plane[3])
        take = surface_mask(points, surface) & (d < distance)
        owner[take], distance[take] = k, d[take]
    return owner


def fit_plane(points, trim=3, keep=0.9):
    """Least-squares plane (n, d) with n·p + d = 0, refitted `trim` times on the `keep` share nearest to it."""
    chosen = points
    for _ in range(trim + 1):
        centre = chosen.mean(axis=0)
        normal = np.linalg.svd(chosen - centre, full_matrices=False)[2][2]
        if abs(normal[2]) > 0.7 and normal[2] < 0:
            normal = -normal
        elif abs(normal[2]) <= 0.7 and normal @ np.array([1.0, 1.0, 0.0]) < 0:
            normal = -normal
        d = -normal @ centre
        residual = np.abs(points @ normal + d)
        chosen = points[residual <= np.quantile(residual, keep)] if len(points) > 10 else points
    return normal, float(d)


def settled_plane(points, surface, rounds=30):
    """The plane a surface's marking settles on: fitted (plain least squares) to the points of its
    region within its tolerance, then to those within the tolerance of that fit, until they stay the
    same. A marked plane that is not its own settled plane was fitted with points of something
    else (room_scan1/2's wall y3.09 with a door recess 13 cm behind it, 1.3-2.7 deg off the wall)."""
    inside = _in_marked_region(points, surface)
    plane = np.array(surface["plane"], dtype=float)
    for _ in range(rounds):
        near = points[inside & (np.abs(points @ plane[:3] + plane[3]) <= surface["tolerance"])]
        if len(near) < 3:
            break
        centre = near.mean(axis=0)
        normal = np.linalg.svd(near - centre, full_matrices=False)[2][2]
        normal = normal if normal @ plane[:3] >= 0 else -normal
        settled = np.append(normal, -normal @ centre)
        if np.allclose(settled, plane, atol=1e-6):
            break
        plane = settled
    return plane


def best_plane_in_region(points, surface, band, trials=400, seed=0):
    """The plane within 15 deg of the marking that holds the most of a surface's region points within its tolerance (RANSAC,
    seeded), settled like the marking, and how many points it holds. A marking that holds clearly
    fewer was fitted to a compromise between two faces (Bobkov's wall x4.72 with a duct 12 cm proud
    of it: both leaned 3.7 deg from the wall, yet settled, as every point of the compromise stays)."""
    inside = points[_in_marked_region(points, surface)]
    if len(inside) < 3:
        return np.array(surface["plane"], dtype=float), 0
    rng = np.random.default_rng(seed)
    marked = np.array(surface["plane"][:3], dtype=float)
    marked /= np.linalg.norm(marked)
    best, held = np.append(marked, surface["plane"][3]), -1
    for _ in range(trials):
        a, b, c = inside[rng.choice(len(inside), 3, replace=False)]
        normal = np.cross(b - a, c - a)
        if np.linalg.norm(normal) < 1e-9:
            continue
        normal /= np.linalg.norm(normal)
        if abs(normal @ marked) < math.cos(math.radians(15)):
            continue  # another surface in the region (a wall in a floor's box), not a compromise
        count = int(np.count_nonzero(np.abs((inside - a) @ normal) <= band))
        if count > held:
            best, held = np.append(normal, -normal @ a), count
    start = dict(surface, plane=list(best))
    settled = settled_plane(points, start)
    return settled, int(np.count_nonzero(np.abs(inside @ settled[:3] + settled[3]) <= band))


def rms_to_plane(points, normal, d):
    return float(np.sqrt(np.mean((points @ normal + d) ** 2))) if len(points) else float("nan")


# ------------------------------------------------------------------ the tools used by hand

def _has_matplotlib():
    """The pictures draw with matplotlib, which neither install script installs."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True


def _scene(name, data):
    sys.path.insert(0, HERE)
    import real_clouds
    for scene_name, scene, why in real_clouds.scenes(data):
        if scene_name == name:
            if scene is None:
                raise SystemExit(f"{name}: {why}")
            return scene
    raise SystemExit(f"no scene {name}")


def views(points, out, title, box=None):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    if box is not None:
        points = points[np.all((points >= box[:3]) & (points <= box[3:]), axis=1)]
    fig, axes = plt.subplots(1, 3, figsize=(21, 7))
    for ax, (i, j, c) in zip(axes, [(0, 1, 2), (0, 2, 1), (1, 2, 0)]):
        order = np.argsort(points[:, c])
        ax.scatter(points[order, i], points[order, j], c=points[order, c], s=0.3, cmap="viridis")
        ax.set_xlabel("xyz"[i]), ax.set_ylabel("xyz"[j]), ax.set_aspect("equal"), ax.grid(True, alpha=0.4)
        ax.set_title(f"{title}: {'xyz'[i]}{'xyz'[j]} coloured by {'xyz'[c]}")
        ax.minorticks_on(), ax.grid(True, which="minor", alpha=0.15)
    fig.tight_layout()
    fig.savefig(out, dpi=70)
    plt.close(fig)


def check_picture(points, annotation, out, title, dpi=60, max_points=60000):
    """Top view and side view of a scene with each annotated surface in its own colour."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    owner = memberships(points, annotation)
    rng = np.random.default_rng(1)
    pick = rng.permutation(len(points))[:max_points]
    p, o = points[pick], owner[pick]
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    colours = plt.get_cmap("tab20")
    for ax, (i, j) in zip(axes, [(0, 1), (0, 2)]):
        ax.scatter(p[o < 0, i], p[o < 0, j], s=0.2, c="0.8")
        for k in np.unique(o[o >= 0]):
            ax.scatter(p[o == k, i], p[o == k, j], s=0.3, color=colours(k % 20))
        ax.set_aspect("equal"), ax.set_xlabel("xyz"[i]), ax.set_ylabel("xyz"[j])
    for k, surface in enumerate(annotation["surfaces"]):
        where = points[owner == k]
        if len(where):
            c = np.median(where, axis=0)
            axes[0].annotate(surface["name"], (c[0], c[1]), fontsize=6)
            axes[1].annotate(surface["name"], (c[0], c[2]), fontsize=6)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=dpi)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("tool", choices=["views", "fit", "check"])
    ap.add_argument("name")
    ap.add_argument("box", nargs="?")
    ap.add_argument("--data", default=os.path.join(os.path.dirname(ROOT), "shared", "data"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "annotate"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    points = _scene(a.name, a.data).world()
    box = np.array([float(v) for v in a.box.split(",")]) if a.box else None
    if a.tool == "views":
        if not _has_matplotlib():
            raise SystemExit("real_annotations: views draws with matplotlib: apt-get install python3-matplotlib")
        out = os.path.join(a.out, f"{a.name}_views{'_' + a.box.replace(',', '_') if a.box else ''}.png")
        views(points, out, a.name, box)
        print(out, len(points), "points; extent", points.min(axis=0).round(2), points.max(axis=0).round(2))
    elif a.tool == "fit":
        inside = points[np.all((points >= box[:3]) & (points <= box[3:]), axis=1)]
        normal, d = fit_plane(inside)
        residual = inside @ normal + d
        near = np.abs(residual) < 0.05
        print(f"{len(inside)} points, plane [{normal[0]:.4f}, {normal[1]:.4f}, {normal[2]:.4f}, {d:.4f}], "
              f"rms {rms_to_plane(inside, normal, d):.4f}, within 5 cm {near.mean():.2f} (rms there {np.sqrt(np.mean(residual[near] ** 2)):.4f}), "
              f"median |r| {np.median(np.abs(residual)):.4f}")
    else:
        annotation = load(a.name)
        owner = memberships(points, annotation)
        for k, surface in enumerate(annotation["surfaces"]):
            mine = points[owner == k]
            plane = np.array(surface["plane"])
            settled = settled_plane(points, surface)
            # Marked normals are rounded to 4 decimals: not quite unit (0.9999 reads as 0.8 deg).
            angle = np.degrees(np.arccos(min(1.0, abs(float(settled[:3] @ plane[:3]) / np.linalg.norm(plane[:3])))))
            warn = "  <- not its own settled plane" if angle > 0.5 else ""
            inside = points[_in_marked_region(points, surface)]
            band = surface["tolerance"] / 2
            holds = int(np.count_nonzero(np.abs(inside @ plane[:3] / np.linalg.norm(plane[:3]) + plane[3]) <= band))
            best, best_holds = best_plane_in_region(points, surface, band)
            best_angle = np.degrees(np.arccos(min(1.0, abs(float(best[:3] @ plane[:3]) / np.linalg.norm(plane[:3])))))
            if best_holds > 1.1 * holds and best_angle > 0.5:
                warn += f"  <- a plane {best_angle:.1f} deg off holds {best_holds} of the region's points, the marking {holds}"
            print(f"{surface['name']:>16} {surface['kind']:>8} {len(mine):7d} pts, rms to plane {rms_to_plane(mine, plane[:3], plane[3]):.4f}, "
                  f"settled plane {angle:.2f} deg off{warn}")
        print(f"{(owner >= 0).mean():.2f} of points on a surface")
        if not _has_matplotlib():
            print("real_annotations: no picture (it draws with matplotlib: apt-get install python3-matplotlib)")
            return
        out = os.path.join(a.out, f"{a.name}_check.png")
        check_picture(points, annotation, out, a.name, dpi=90)
        print(out)


if __name__ == "__main__":
    main()

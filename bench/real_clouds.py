"""The real scans of ../shared/data as numpy arrays, in the frame their annotations use.

Each scan is read here, independently of mlmap's readers, so that the annotations
(bench/annotations/*.json) never depend on mlmap's registration or up-axis handling:

- 3DTK (.3d, cm, left-handed, y up, z forward) goes into mlmap's right-handed z-up frame the
  way src/io/threedtk.cpp documents it (x_r = z, y_r = -x, z_r = y, metres), and into the
  world by its own .pose file (R_r = A R_L Aᵀ, t_r = A t_L / 100), not by mlmap's registration;
- PCD files keep their coordinates; office1.pcd's VIEWPOINT (a half turn about x) makes the
  camera's y-down frame y-up, and it is then turned a quarter turn about x into z-up here;
- duplicated points (the PCL room scans store each line twice, the ANYmal stair map repeats
  every triangle vertex) are kept once, in the order they first appear;
- 3DTK's no-return readings (3276 cm) and those closer than its config's 48 cm are dropped.
"""
import bz2, ctypes, ctypes.util, math, os

import numpy as np

# 3DTK's dat/config.ini keeps readings in [48, 3276) cm; 3276 cm is the scanner's "no return".
THREEDTK_MIN_RANGE_M, THREEDTK_MAX_RANGE_M = 0.48, 32.7

# The sensor origin plane_seg's test code gives for tilted-steps.pcd (its README).
TILTED_STEPS_SENSOR = np.array([0.248091, 0.012443, 1.806473])

# 3DTK (left-handed, y up, z forward) -> mlmap (right-handed, z up, x forward).
AXIS_3DTK = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])

# y up -> z up, a proper rotation (a quarter turn about x): (x, y, z) -> (x, -z, y).
Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


def _rotation(axis, degrees):
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    r = np.eye(3)
    r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
    return r


def threedtk_pose(path):
    """The .pose file's pose in mlmap's frame: (R, t) with world = R p + t."""
    values = [float(v) for v in open(path).read().split()]
    if len(values) != 6:
        raise ValueError(f"{path}: expected 6 numbers, found {len(values)}")
    r_l = _rotation(0, values[3]) @ _rotation(1, values[4]) @ _rotation(2, values[5])
    return AXIS_3DTK @ r_l @ AXIS_3DTK.T, AXIS_3DTK @ np.array(values[:3]) / 100.0


def read_threedtk(path):
    """Points of one .3d file in the scanner's frame (mlmap's axes, metres), readings out of range dropped."""
    points = np.loadtxt(path, dtype=np.float64, ndmin=2)[:, :3] @ AXIS_3DTK.T / 100.0
    ranges = np.linalg.norm(points, axis=1)
    return points[(ranges >= THREEDTK_MIN_RANGE_M) & (ranges < THREEDTK_MAX_RANGE_M)]


def _lzf_decompress(data, size):
    library = ctypes.util.find_library("lzf")
    if library:
        lzf = ctypes.CDLL(library)
        out = ctypes.create_string_buffer(size)
        got = lzf.lzf_decompress(data, len(data), out, size)
        if got != size:
            raise ValueError(f"LZF block gave {got} bytes, expected {size}")
        return out.raw
    out, i = bytearray(), 0  # plain Python, when liblzf is not installed
    while i < len(data):
        control = data[i]
        i += 1
        if control < 32:
            out += data[i:i + control + 1]
            i += control + 1
            continue
        length = control >> 5
        if length == 7:
            length += data[i]
            i += 1
        start = len(out) - ((control & 0x1F) << 8) - data[i] - 1
        i += 1
        for k in range(length + 2):
            out.append(out[start + k])
    return bytes(out)


def read_pcd(path):
    """(points N x 3, header dict, extra fields dict) of a PCD file; NaN points dropped."""
    raw = open(path, "rb").read()
    header, offset = {}, 0
    while True:
        end = raw.index(b"\n", offset)
        line = raw[offset:end].decode("ascii").strip()
        offset = end + 1
        if not line or line.startswith("#"):
            continue
        key, *values = line.split()
        header[key] = values
        if key == "DATA":
            break
    names, sizes = header["FIELDS"], [int(s) for s in header["SIZE"]]
    types, counts = header["TYPE"], [int(c) for c in header.get("COUNT", ["1"] * len(names))]
    n = int(header["POINTS"][0])
    kinds = {("F", 4): "<f4", ("F", 8): "<f8", ("U", 4): "<u4", ("I", 4): "<i4", ("U", 1): "u1", ("I", 1): "i1",
             ("U", 2): "<u2", ("I", 2): "<i2"}
    dtype = [(name, kinds[(t, s)], (c,)) if c > 1 else (name, kinds[(t, s)]) for name, s, t, c in
             zip(names, sizes, types, counts)]
    encoding = header["DATA"][0]
    if encoding == "ascii":
        table = np.loadtxt(raw[offset:].decode("ascii").splitlines(), dtype=np.float64, ndmin=2)
        columns = {name: table[:, k] for k, name in enumerate(names)}
    elif encoding == "binary":
        cloud = np.frombuffer(raw, dtype=np.dtype(dtype), count=n, offset=offset)
        columns = {name: cloud[name].astype(np.float64) for name in names}
    elif encoding == "binary_compressed":
        packed, unpacked = np.frombuffer(raw, dtype="<u4", count=2, offset=offset)
        body = _lzf_decompress(raw[offset + 8:offset + 8 + int(packed)], int(unpacked))
        columns, start = {}, 0
        for (name, *kind) in dtype:  # field by field: all x, then all y, ...
            width = np.dtype(kind[0]).itemsize * (kind[1][0] if len(kind) > 1 else 1)
            columns[name] = np.frombuffer(body, dtype=kind[0], count=n * (width // np.dtype(kind[0]).itemsize),
                                          offset=start).astype(np.float64)
            start += width * n
    else:
        raise ValueError(f"{path}: DATA {encoding} not read here")
    points = np.stack([columns["x"], columns["y"], columns["z"]], axis=1)
    keep = np.isfinite(points).all(axis=1)
    extra = {name: column[keep] for name, column in columns.items() if name not in "xyz"}
    return points[keep], header, extra


def viewpoint_rotation(header):
    """Rotation of a PCD VIEWPOINT (its translation is zero in every file used here)."""
    tx, ty, tz, w, x, y, z = (float(v) for v in header.get("VIEWPOINT", "0 0 0 1 0 0 0".split()))
    norm = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / norm, x / norm, y / norm, z / norm
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]), np.array([tx, ty, tz])


def unique_in_order(points):
    _, first = np.unique(points, axis=0, return_index=True)
    return points[np.sort(first)]


def read_xyz_bz2(path):
    with bz2.open(path, "rt") as text:
        return np.loadtxt(text, dtype=np.float64, ndmin=2)[:, :3]


class Scene:
    """One annotated scene: its scans (sensor frame, as mlmap is given them), their poses, and how to run mlmap.

    scans: list of (points in the scan's own frame, R, t); world = R p + t is the annotation frame.
    up: the axis that is up in the frame mlmap is given (\"z\" or \"y\"); y-up scenes are
    annotated in their z-up turn (Y_UP_TO_Z_UP applied after the pose).
    register: whether mlmap registers the scans (from these poses) before building.
    sensor_known: whether each scan's frame has its sensor at the origin (else the points are
    registered world points: Bobkov's cloud, the ANYmal elevation map).
    """

    def __init__(self, name, title, scans, up="z", register=False, sensor_known=True):
        self.name, self.title, self.scans, self.up, self.register = name, title, scans, up, register
        self.sensor_known = sensor_known

    def world(self):
        """All points in the annotation frame (z up), in mlmap's input order."""
        parts = [p @ r.T + t for p, r, t in self.scans]
        points = np.concatenate(parts)
        return points @ Y_UP_TO_Z_UP.T if self.up == "y" else points


def scenes(data):
    """(name, Scene or None, message) for every scan set of ../shared/data; None where files are missing."""
    found = []

    def need(*paths):
        missing = [p for p in paths if not os.path.exists(os.path.join(data, p))]
        return None if not missing else f"missing {', '.join(missing)}"

    def add(name, paths, make):
        why = need(*paths)
        found.append((name, None if why else make(*[os.path.join(data, p) for p in paths]), why))

    def threedtk(*paths):
        scans = []
        for k in range(0, len(paths), 2):
            r, t = threedtk_pose(paths[k + 1])
            scans.append((read_threedtk(paths[k]), r, t))
        return Scene("3dtk", "3DTK's three scans (registered from their .pose files)", scans, register=True)

    add("3dtk", [f"3dtk_dat_3scans/scan00{k}.{e}" for k in range(3) for e in ("3d", "pose")], threedtk)
    add("fr079", ["octomap_share_samples/scan.dat.bz2"],
        lambda p: Scene("fr079", "OctoMap's scan.dat (one scan, building 079)", [(read_xyz_bz2(p), np.eye(3), np.zeros(3))]))

    def bobkov(p):
        points, _, _ = read_pcd(p)
        return Scene("bobkov_room2", "Bobkov et al. room 2 (registered mobile-scanner cloud)",
                     [(points[1:], np.eye(3), np.zeros(3))], sensor_known=False)  # the first line is a stray "0 0 1.5"

    add("bobkov_room2", ["bobkov_office_labels/room2_gt_fine.pcd"], bobkov)

    def office1(p):
        points, header, _ = read_pcd(p)
        r, t = viewpoint_rotation(header)
        return Scene("office1", "PCL's office1.pcd (Kinect-type camera, y up by its VIEWPOINT)",
                     [(points, r, t)], up="y")

    add("office1", ["pcl_test_indoor/office1.pcd"], office1)
    for k in (1, 2):
        add(f"room_scan{k}", [f"pcl_room_scans/room_scan{k}.pcd"],
            lambda p, k=k: Scene(f"room_scan{k}", f"PCL's room_scan{k}.pcd (360° laser scan)",
                                 [(unique_in_order(read_pcd(p)[0]), np.eye(3), np.zeros(3))]))
    add("stairs_anymal", ["plane_seg_stairs/ori_entrance_stair_climb_06.pcd"],
        lambda p: Scene("stairs_anymal", "plane_seg's ANYmal stair elevation map (2 cm grid)",
                        [(unique_in_order(read_pcd(p)[0]), np.eye(3), np.zeros(3))], sensor_known=False))
    add("tilted_steps", ["plane_seg_stairs/tilted-steps.pcd"],
        lambda p: Scene("tilted_steps", "plane_seg's DRC tilted-steps lidar scan (Atlas)",
                        [(read_pcd(p)[0] - TILTED_STEPS_SENSOR, np.eye(3), TILTED_STEPS_SENSOR)]))
    return found

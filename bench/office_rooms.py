#!/usr/bin/python3
"""Offices generated from a seed, for the plane benchmarks (bench/planes_sweep.py
--scenes office-1,office-2,...): what the shipped lab holds fixed, varied. A room of
random size and height; one to three clusters of desks, each a row of one to three
desks at a random turn, neighbours touching with tops 1-3 cm apart or 0.1-0.6 m apart;
office chairs (seat, back, column) in front of most desks; monitors on the desks; a
sideboard or a cabinet against a wall; a whiteboard 1 cm proud of a wall; three scan
poses in the free floor. Every face is its own true plane (touching desks are two
tables); walls, floor, ceiling and the desk and sideboard tops carry their classes, the
rest is "other".

    /usr/bin/python3 bench/office_rooms.py SEED > office.json   (the scene, to look at)
    /usr/bin/python3 bench/office_rooms.py hall-SEED > hall.json (hall_room: a large hall, sparse far half)
"""
import json
import math
import sys

import numpy as np

# The lab's laser (maps/lab.json) with 1 cm range noise.
PATTERN = {"field_of_view_deg": 270, "angular_step_deg": 0.25, "tilt_start_deg": -46, "tilt_end_deg": 46,
           "tilt_step_deg": 0.4, "min_range": 0.023, "max_range": 30, "range_sigma": 0.01, "mount_height": 1.2}


def rect(lo, hi, cls, facing=None):
    r = {"type": "rectangle", "class": cls, "min": lo, "max": hi}
    if facing:
        r["facing"] = facing
    return r


def turned(cx, cy, yaw_deg, u, v):
    c, s = math.cos(math.radians(yaw_deg)), math.sin(math.radians(yaw_deg))
    return cx + c * u - s * v, cy + s * u + c * v


def box(center, size, yaw_deg, cls="other", classes=None, omit=None):
    b = {"type": "box", "class": cls, "center": [float(x) for x in center], "size": [float(x) for x in size],
         "yaw_deg": float(yaw_deg)}
    if classes:
        b["classes"] = classes
    if omit:
        b["omit"] = omit
    return b


def cylinder(x, y, radius, z0, z1):
    return {"type": "cylinder", "center": [float(x), float(y)], "radius": float(radius), "z": [float(z0), float(z1)]}


def desk_row(rng, cx, cy, yaw):
    """A row of desks along the row's u axis, chairs on its -v side. Returns (surfaces,
    footprint radius)."""
    count = int(rng.integers(1, 4))
    length, depth = rng.uniform(1.2, 1.6), rng.uniform(0.7, 0.8)
    touching = rng.random() < 0.4
    gaps = [0.0 if touching else rng.uniform(0.1, 0.6) for _ in range(count - 1)]
    span = count * length + sum(gaps)
    surfaces, u = [], -span / 2
    for k in range(count):
        top = rng.uniform(0.72, 0.76)
        if touching and k > 0:  # touching tops differ by 1-3 cm, either way
            top = previous_top + rng.choice([-1, 1]) * rng.uniform(0.01, 0.03)
        previous_top = top
        mu = u + length / 2
        x, y = turned(cx, cy, yaw, mu, 0.0)
        surfaces.append(box([x, y, top - 0.015], [length, depth, 0.03], yaw, classes={"top": "table"}))
        for lu, lv in ((-1, -1), (-1, 1), (1, -1), (1, 1)):
            lx, ly = turned(cx, cy, yaw, mu + lu * (length / 2 - 0.05), lv * (depth / 2 - 0.05))
            surfaces.append(cylinder(lx, ly, 0.025, 0.0, top - 0.03))
        if rng.random() < 0.7:  # a monitor towards the back edge
            mx, my = turned(cx, cy, yaw, mu + rng.uniform(-0.3, 0.3), depth / 2 - 0.15)
            surfaces.append(box([mx, my, top + 0.2], [0.55, 0.05, 0.33], yaw + rng.uniform(-15, 15)))
        if rng.random() < 0.75:  # an office chair in front
            seat_top = rng.uniform(0.42, 0.5)
            back_from_edge = rng.uniform(0.2, 0.55)
            chair_yaw = yaw + rng.uniform(-30, 30)
            sx, sy = turned(cx, cy, yaw, mu + rng.uniform(-0.2, 0.2), -depth / 2 - back_from_edge)
            surfaces.append(box([sx, sy, seat_top - 0.03], [0.46, 0.46, 0.06], chair_yaw))
            bx, by = turned(sx, sy, chair_yaw, 0.0, -0.25)
            surfaces.append(box([bx, by, seat_top + 0.3], [0.44, 0.04, 0.42], chair_yaw))
            surfaces.append(cylinder(sx, sy, 0.03, 0.05, seat_top - 0.06))
        u += length + (gaps[k] if k < count - 1 else 0.0)
    return surfaces, math.hypot(span / 2, depth / 2 + 1.0)


def office_room(seed):
    rng = np.random.default_rng(5000 + seed)
    w, d, h = rng.uniform(4.5, 9.0), rng.uniform(3.5, 7.0), rng.uniform(2.5, 3.2)
    surfaces = [rect([0, 0, 0], [w, d, 0], "floor"), rect([0, 0, h], [w, d, h], "ceiling"),
                rect([0, 0, 0], [0, d, h], "wall", "+x"), rect([w, 0, 0], [w, d, h], "wall", "-x"),
                rect([0, 0, 0], [w, 0, h], "wall", "+y"), rect([0, d, 0], [w, d, h], "wall", "-y")]
    taken = []  # (x, y, radius) of what stands on the floor
    # Against the south wall: a sideboard (its top a table) or a tall cabinet.
    length = rng.uniform(1.0, min(2.4, w - 1.0))
    x0 = rng.uniform(0.3, w - length - 0.3)
    if rng.random() < 0.6:
        height, cls = rng.uniform(0.8, 1.0), {"top": "table"}
    else:
        height, cls = rng.uniform(1.8, 2.1), None
    surfaces.append({"type": "box", "class": "other", "min": [x0, 0.0, 0.0], "max": [x0 + length, 0.45, height],
                     "omit": ["bottom", "y-"], **({"classes": cls} if cls else {})})
    taken.append((x0 + length / 2, 0.3, length / 2 + 0.3))
    # A whiteboard 1 cm proud of the north wall.
    bw = rng.uniform(1.0, min(2.0, w - 1.0))
    bx = rng.uniform(0.3, w - bw - 0.3)
    surfaces.append(rect([bx, d - 0.01, 0.9], [bx + bw, d - 0.01, 2.0], "other", "-y"))
    for _ in range(int(rng.integers(1, 4))):
        for _ in range(100):
            cx, cy, yaw = rng.uniform(1.2, w - 1.2), rng.uniform(1.2, d - 1.2), rng.uniform(-90, 90)
            row, radius = desk_row(rng, cx, cy, yaw)
            fits = all(math.hypot(cx - x, cy - y) > radius + r for x, y, r in taken)
            inside = radius < min(cx, cy, w - cx, d - cy) + 0.8
            if fits and inside:
                surfaces += row
                taken.append((cx, cy, radius))
                break
    poses = []
    for _ in range(400):
        if len(poses) == 3:
            break
        x, y = rng.uniform(0.8, w - 0.8), rng.uniform(0.8, d - 0.8)
        if all(math.hypot(x - tx, y - ty) > r * 0.6 + 0.4 for tx, ty, r in taken) and \
                all(math.hypot(x - p["x"], y - p["y"]) > 1.0 for p in poses):
            poses.append({"x": float(x), "y": float(y), "yaw_deg": float(rng.uniform(-180, 180))})
    if not poses:
        poses = [{"x": w / 2, "y": d / 2, "yaw_deg": 0.0}]
    return {"name": f"office-{seed}", "scan_pattern": dict(PATTERN, seed=seed), "poses": poses,
            "surfaces": surfaces}


def hall_room(seed):
    """A hall 12-18 m long scanned from near one end by a coarser laser (0.5 deg steps,
    1 deg tilt steps): its far floor, ceiling and walls are scan lines tens of cm apart,
    as a real scan's far half is. Desk rows, a sideboard or a cabinet; one or two poses."""
    rng = np.random.default_rng(9000 + seed)
    w, d, h = rng.uniform(12.0, 18.0), rng.uniform(6.0, 10.0), rng.uniform(2.8, 4.0)
    surfaces = [rect([0, 0, 0], [w, d, 0], "floor"), rect([0, 0, h], [w, d, h], "ceiling"),
                rect([0, 0, 0], [0, d, h], "wall", "+x"), rect([w, 0, 0], [w, d, h], "wall", "-x"),
                rect([0, 0, 0], [w, 0, h], "wall", "+y"), rect([0, d, 0], [w, d, h], "wall", "-y")]
    taken = []
    length = rng.uniform(1.5, 3.0)
    x0 = rng.uniform(4.0, w - length - 0.5)
    height = rng.uniform(0.8, 1.0) if rng.random() < 0.6 else rng.uniform(1.8, 2.1)
    surfaces.append({"type": "box", "class": "other", "min": [x0, 0.0, 0.0], "max": [x0 + length, 0.45, height],
                     "omit": ["bottom", "y-"], **({"classes": {"top": "table"}} if height < 1.2 else {})})
    taken.append((x0 + length / 2, 0.3, length / 2 + 0.3))
    for _ in range(int(rng.integers(2, 5))):
        for _ in range(100):
            cx, cy, yaw = rng.uniform(3.0, w - 1.5), rng.uniform(1.5, d - 1.5), rng.uniform(-90, 90)
            row, radius = desk_row(rng, cx, cy, yaw)
            if all(math.hypot(cx - x, cy - y) > radius + r for x, y, r in taken) and \
                    radius < min(cx, cy, w - cx, d - cy) + 0.8:
                surfaces += row
                taken.append((cx, cy, radius))
                break
    poses = [{"x": float(rng.uniform(1.0, 2.5)), "y": float(rng.uniform(1.5, d - 1.5)),
              "yaw_deg": float(rng.uniform(-30, 30))}]
    if rng.random() < 0.5:
        poses.append({"x": float(rng.uniform(2.5, 4.0)), "y": float(rng.uniform(1.5, d - 1.5)),
                      "yaw_deg": float(rng.uniform(-30, 30))})
    pattern = dict(PATTERN, seed=seed, angular_step_deg=0.5, tilt_step_deg=1.0)
    return {"name": f"hall-{seed}", "scan_pattern": pattern, "poses": poses, "surfaces": surfaces}


if __name__ == "__main__":
    kind, _, number = (sys.argv[1] if len(sys.argv) > 1 else "1").rpartition("-")
    make = hall_room if kind == "hall" else office_room
    json.dump(make(int(number)), sys.stdout, indent=1)

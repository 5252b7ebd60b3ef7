#!/usr/bin/env python3
"""How exact a TUM recording's ground truth is from one frame to the next, and each estimate's
frame-to-frame rotation error against it taken two ways.

TUM's tools pair every frame with the nearest ground-truth pose (within 20 ms). The motion-capture
poses come at 100 Hz, so on a fast turn the nearest one can be up to 5 ms off the frame: at 100
deg/s that is 0.5 deg per pose. This script measures that resolution (nearest pose against the
pose interpolated at the frame's time, slerp for the rotation) and the gap between the colour and
the depth timestamps, then prints each estimate's frame-to-frame rotation errors against both.

Usage: ground_truth_resolution.py DATASET_DIR [TRAJECTORY.txt ...]
(trajectories in TUM format, stamped with the depth images' times as nidevo-run and nidevo-bench
write them). Standard library only.
"""
import bisect
import math
import os
import sys

MAX_DIFFERENCE_S = 0.02  # TUM's associate.py default
SPEED_BINS_DEG = [(0, 1), (1, 2), (2, 3), (3, math.inf)]


def read_rows(path):
    rows = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#"):
                rows.append(line.split())
    return rows


def read_poses(path):
    """[(t, (tx, ty, tz), (qx, qy, qz, qw))] sorted by time."""
    poses = []
    for r in read_rows(path):
        v = [float(x) for x in r[:8]]
        poses.append((v[0], tuple(v[1:4]), normalised(tuple(v[4:8]))))
    return sorted(poses)


def normalised(q):
    n = math.sqrt(sum(c * c for c in q))
    return tuple(c / n for c in q)


def multiply(a, b):  # Hamilton product, (x, y, z, w)
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def conjugate(q):
    return (-q[0], -q[1], -q[2], q[3])


def angle_deg(q):
    return math.degrees(2 * math.atan2(math.sqrt(q[0] ** 2 + q[1] ** 2 + q[2] ** 2), abs(q[3])))


def slerp(a, b, w):
    dot = sum(x * y for x, y in zip(a, b))
    if dot < 0:
        b, dot = tuple(-c for c in b), -dot
    if dot > 0.9995:
        return normalised(tuple(x + w * (y - x) for x, y in zip(a, b)))
    theta = math.acos(dot)
    sa, sb = math.sin((1 - w) * theta) / math.sin(theta), math.sin(w * theta) / math.sin(theta)
    return tuple(sa * x + sb * y for x, y in zip(a, b))


class GroundTruth:
    def __init__(self, path):
        self.poses = read_poses(path)
        self.times = [p[0] for p in self.poses]

    def nearest(self, t):
        i = bisect.bisect_left(self.times, t)
        best = min((j for j in (i - 1, i) if 0 <= j < len(self.times)),
                   key=lambda j: abs(self.times[j] - t))
        return self.poses[best][2] if abs(self.times[best] - t) <= MAX_DIFFERENCE_S else None

    def interpolated(self, t):
        i = bisect.bisect_left(self.times, t)
        if i == 0 or i == len(self.times):
            return None
        (t0, _, q0), (t1, _, q1) = self.poses[i - 1], self.poses[i]
        if t1 - t0 > MAX_DIFFERENCE_S:
            return None
        return slerp(q0, q1, (t - t0) / (t1 - t0))


def relative(qa, qb):
    return multiply(conjugate(qa), qb)


def nearest_rank(sorted_values, q):
    v = sorted_values
    return v[min(len(v), max(1, math.ceil(q * len(v)))) - 1]


def summary(values):
    v = sorted(values)
    if not v:
        return "no frames"
    rank = lambda q: nearest_rank(v, q)
    rmse = math.sqrt(sum(x * x for x in v) / len(v))
    return (f"median {rank(0.5):.3f}  p95 {rank(0.95):.3f}  rmse {rmse:.3f}  max {v[-1]:.2f} deg"
            f"  (over 2 deg: {sum(x > 2 for x in v)} of {len(v)})")


def frame_times(dataset):
    """Colour and depth timestamps of each associated frame."""
    assoc = os.path.join(dataset, "associations.txt")
    if not os.path.exists(assoc):
        sys.exit(f"{assoc}: missing (this script reads the colour/depth pairs from it)")
    rows = read_rows(assoc)
    # TUM's associate.py writes rgb first; some tools write depth first.
    rgb_first = rows[0][1].startswith("rgb")
    return [(float(r[0]), float(r[2])) if rgb_first else (float(r[2]), float(r[0])) for r in rows]


def main(argv):
    if len(argv) < 2:
        sys.exit(__doc__)
    dataset = argv[1]
    gt = GroundTruth(os.path.join(dataset, "groundtruth.txt"))
    times = frame_times(dataset)
    pose_gap, stamp_gap = [], []
    for (c0, d0), (c1, d1) in zip(times, times[1:]):
        n0, n1, i0, i1 = gt.nearest(d0), gt.nearest(d1), gt.interpolated(d0), gt.interpolated(d1)
        if None in (n0, n1, i0, i1):
            continue
        pose_gap.append(angle_deg(relative(relative(n0, n1), relative(i0, i1))))
        j0, j1 = gt.interpolated(c0), gt.interpolated(c1)
        if None not in (j0, j1):
            stamp_gap.append(angle_deg(relative(relative(i0, i1), relative(j0, j1))))
    print(f"{dataset}: {len(times)} frames, ground truth {len(gt.times)} poses")
    print(f"ground truth frame to frame, nearest pose against interpolated: {summary(pose_gap)}")
    print(f"ground truth frame to frame, depth against colour timestamps:  {summary(stamp_gap)}")
    for path in argv[2:]:
        estimate = read_poses(path)
        errors = {"nearest": [], "interpolated": []}
        by_speed = {bounds: [] for bounds in SPEED_BINS_DEG}  # interpolated, by true rotation
        for (ta, _, qa), (tb, _, qb) in zip(estimate, estimate[1:]):
            moved = relative(qa, qb)
            for kind, lookup in (("nearest", gt.nearest), ("interpolated", gt.interpolated)):
                ga, gb = lookup(ta), lookup(tb)
                if None in (ga, gb):
                    continue
                error = angle_deg(relative(relative(ga, gb), moved))
                errors[kind].append(error)
                if kind == "interpolated":
                    true_deg = angle_deg(relative(ga, gb))
                    for lo, hi in SPEED_BINS_DEG:
                        if lo <= true_deg < hi:
                            by_speed[(lo, hi)].append(error)
        print(f"{os.path.basename(path)}:")
        for kind, values in errors.items():
            print(f"  rotation error against the {kind:12s} ground truth: {summary(values)}")
        parts = []
        for (lo, hi), values in by_speed.items():
            v = sorted(values)
            if v:
                parts.append(f"[{lo:g}, {hi:g}) n={len(v)} median {nearest_rank(v, 0.5):.2f} "
                             f"p90 {nearest_rank(v, 0.9):.2f}")
        print("  interpolated, by true rotation per frame (deg): " + "; ".join(parts))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

#!/usr/bin/env python3
"""The pose check's reported spread (sigma) against the frame-to-frame error, over OK frames.

Reads frame CSVs of nidevo-run --frames_csv. The OK frames with ground truth are sorted by
sigma and cut at its quantiles; per part: the median sigma, the error's median and p95, and the
median error over sigma. For rotation (deg) and translation (m), with the rank correlation.
A frame's sigma is the root of the sum of squares of its own and the previous frame's (the
error is that of the motion between them).
Usage: scripts/sigma_table.py FRAMES.csv [...]
"""
import csv
import math
import sys

PARTS = ((0.0, 0.25), (0.25, 0.5), (0.5, 0.75), (0.75, 0.95), (0.95, 1.0))


def quantile(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))] if values else float("nan")


def ranks(values):
    order = sorted(range(len(values)), key=lambda i: values[i])
    out = [0] * len(values)
    for rank, i in enumerate(order):
        out[i] = rank
    return out


def spearman(a, b):
    ra, rb = ranks(a), ranks(b)
    n = len(a)
    ma, mb = sum(ra) / n, sum(rb) / n
    cov = sum((x - ma) * (y - mb) for x, y in zip(ra, rb))
    va = sum((x - ma) ** 2 for x in ra)
    vb = sum((y - mb) ** 2 for y in rb)
    return cov / math.sqrt(va * vb) if va and vb else float("nan")


def ok_frames(paths):
    """(sigma_rot, err_rot, sigma_t, err_t) per OK frame whose previous frame was checked too."""
    rows = []
    for path in paths:
        prev = None
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                checked = float(r["sigma_rotation_deg"]) > 0
                if (r["state"] == "OK" and r["rotation_error_deg"] != "" and checked and prev):
                    rows.append((math.hypot(float(r["sigma_rotation_deg"]),
                                            float(prev["sigma_rotation_deg"])),
                                 float(r["rotation_error_deg"]),
                                 math.hypot(float(r["sigma_translation_m"]),
                                            float(prev["sigma_translation_m"])),
                                 float(r["translation_error_m"])))
                prev = r if checked else None
    return rows


def main(paths):
    rows = ok_frames(paths)
    if len(rows) < 10:
        sys.exit("sigma_table.py: fewer than 10 OK frames with ground truth")
    for name, s, e, fmt in (("rotation, deg", 0, 1, "{:8.4f}"), ("translation, m", 2, 3, "{:8.5f}")):
        rows.sort(key=lambda x: x[s])
        n = len(rows)
        rho = spearman([x[s] for x in rows], [x[e] for x in rows])
        print(f"{name}: {n} OK frames, rank correlation of sigma and error {rho:.2f}")
        print(f"{'sigma part':>12} {'sigma':>8} {'err med':>8} {'err p95':>8} {'med/sigma':>9}")
        for lo, hi in PARTS:
            part = rows[int(lo * n):int(hi * n)]
            sig = [x[s] for x in part]
            err = [x[e] for x in part]
            ratio = quantile([b / a for a, b in zip(sig, err) if a > 0], 0.5)
            print(f"{f'{lo:.2f}-{hi:.2f}':>12} " + " ".join(
                fmt.format(v) for v in (quantile(sig, 0.5), quantile(err, 0.5), quantile(err, 0.95)))
                  + f" {ratio:9.1f}")


if __name__ == "__main__":
    if len(sys.argv) < 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0 if len(sys.argv) > 1 else 2)
    main(sys.argv[1:])

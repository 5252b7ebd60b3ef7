#!/usr/bin/env python3
"""Per-status error table from nidevo-run --frames_csv files: for OK, DEGRADED and LOST frames,
the median and p95 frame-to-frame rotation and translation error against ground truth, and how
many are over 2 deg or 5 cm (for OK frames: the silent failures).
Usage: scripts/status_table.py FRAMES.csv [...]"""
import csv
import sys


def percentile(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))] if values else float("nan")


def main(paths):
    rows = []
    for path in paths:
        with open(path, newline="") as f:
            rows += [r for r in csv.DictReader(f) if r["rotation_error_deg"]]
    if not rows:
        sys.exit("status_table.py: no frame with ground truth in " + " ".join(paths))
    print(f"{'state':9s} {'frames':>7s} {'share':>6s} {'rot med':>8s} {'rot p95':>8s} "
          f"{'t med m':>8s} {'t p95 m':>8s} {'>2deg/5cm':>10s}")
    for state in ("OK", "DEGRADED", "LOST"):
        sel = [r for r in rows if r["state"] == state]
        rot = [float(r["rotation_error_deg"]) for r in sel]
        tr = [float(r["translation_error_m"]) for r in sel]
        bad = sum(1 for a, b in zip(rot, tr) if a > 2 or b > 0.05)
        print(f"{state:9s} {len(sel):7d} {len(sel) / len(rows):6.1%} {percentile(rot, .5):8.3f} "
              f"{percentile(rot, .95):8.3f} {percentile(tr, .5):8.4f} {percentile(tr, .95):8.4f} "
              f"{bad:10d}")


if __name__ == "__main__":
    if len(sys.argv) < 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0 if len(sys.argv) > 1 else 2)
    main(sys.argv[1:])

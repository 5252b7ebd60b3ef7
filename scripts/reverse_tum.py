#!/usr/bin/env python3
"""Writes a TUM RGB-D folder that plays a recording backwards: the same images, in reverse order,
with time mirrored (t' = t_first + t_last - t) in rgb.txt, depth.txt, associations.txt and
groundtruth.txt. The images are linked, not copied. Every motion of the original is then met
in reverse, after other frames: a second real sequence from one recording, to check a default
on real sensor data that it was not chosen on.

Usage: scripts/reverse_tum.py SRC DST
"""
import os
import sys


def read_rows(path):
    """(comment lines, rows of fields) of a TUM list file; rows keep their text fields."""
    comments, rows = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                comments.append(line.rstrip("\n"))
            else:
                rows.append(line.split())
    return comments, rows


def main(argv):
    if len(argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    src, dst = os.path.abspath(argv[1]), argv[2]
    if not os.path.isfile(os.path.join(src, "depth.txt")):
        sys.stderr.write(f"reverse_tum: {src} has no depth.txt (not a TUM RGB-D folder)\n")
        return 1
    _, depth_rows = read_rows(os.path.join(src, "depth.txt"))
    if not depth_rows:
        sys.stderr.write(f"reverse_tum: {src}/depth.txt lists no frame\n")
        return 1
    stamps = [float(r[0]) for r in depth_rows]
    mirror = min(stamps) + max(stamps)
    os.makedirs(dst, exist_ok=True)
    for folder in ("rgb", "depth"):
        link = os.path.join(dst, folder)
        if not os.path.lexists(link):
            os.symlink(os.path.join(src, folder), link)
    # Time fields: the first of every row; associations.txt also has one in its third field.
    for name, time_fields in (("rgb.txt", [0]), ("depth.txt", [0]), ("groundtruth.txt", [0]),
                              ("associations.txt", [0, 2])):
        path = os.path.join(src, name)
        if not os.path.exists(path):
            continue
        comments, rows = read_rows(path)
        for row in rows:
            for k in time_fields:
                row[k] = f"{mirror - float(row[k]):.6f}"
        rows.sort(key=lambda r: float(r[0]))
        with open(os.path.join(dst, name), "w") as f:
            for line in comments:
                f.write(line + "\n")
            for row in rows:
                f.write(" ".join(row) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

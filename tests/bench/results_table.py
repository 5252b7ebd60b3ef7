#!/usr/bin/env python3
"""nidevo-bench's CSV (--csv) as the README's Markdown tables: one row per sequence, one column
per method, "ATE (silent failures)" with the lowest ATE of the row in bold; then the median time
per frame of each method, and its ratio to NIDEVO's, as medians over the sequences.

Usage: tests/bench/results_table.py RESULTS.csv
"""
import csv
import statistics
import sys


def main(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"results_table.py: no result in {path}")
    methods = list(dict.fromkeys(r["method"] for r in rows))
    sequences = list(dict.fromkeys(r["sequence"] for r in rows))
    cell = {(r["sequence"], r["method"]): r for r in rows}
    print("| sequence | " + " | ".join(methods) + " |")
    print("|---" * (len(methods) + 1) + "|")
    for s in sequences:
        present = [cell[(s, m)] for m in methods if (s, m) in cell]
        best = min(float(r["ate_rmse_m"]) for r in present)
        out = []
        for m in methods:
            r = cell.get((s, m))
            if r is None:
                out.append("-")
                continue
            ate = float(r["ate_rmse_m"])
            text = f"{ate:.4f} ({r['silent_failures']})"
            out.append(f"**{text}**" if ate == best else text)
        print(f"| {s} ({present[0]['frames']} frames) | " + " | ".join(out) + " |")
    print()
    print("| method | median ms per frame | time / nidevo |")
    print("|---|---|---|")
    for m in methods:
        times = [float(cell[(s, m)]["median_ms"]) for s in sequences if (s, m) in cell]
        ratios = [float(cell[(s, m)]["median_ms"]) / float(cell[(s, "nidevo")]["median_ms"])
                  for s in sequences if (s, m) in cell and (s, "nidevo") in cell]
        ratio = f"x{statistics.median(ratios):.2f}" if ratios else "-"
        print(f"| {m} | {statistics.median(times):.2f} | {ratio} |")


if __name__ == "__main__":
    if len(sys.argv) != 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0 if len(sys.argv) == 2 else 2)
    main(sys.argv[1])

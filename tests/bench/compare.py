#!/usr/bin/env python3
"""A/B timing of two builds of a Google Benchmark binary on a shared, noisy machine.

Runs the two binaries alternately, round after round, so that both see the same background load,
and prints per benchmark the minimum and median of each and the ratio of the medians (new/old).

Usage: tests/bench/compare.py OLD_BINARY NEW_BINARY [--filter REGEX] [--rounds N]
Example (the code before and after a change):
  git worktree add /tmp/old <commit> && cmake -S /tmp/old -B /tmp/old/build -G Ninja \
      -DNIDEVO_BUILD_SERVICE=OFF -DNIDEVO_BUILD_TESTS=OFF && cmake --build /tmp/old/build
  tests/bench/compare.py /tmp/old/build/bin/nidevo_bench build/bin/nidevo_bench
"""
import argparse
import json
import statistics
import subprocess


def run(binary, regex):
    out = subprocess.run(
        [binary, "--benchmark_filter=" + regex, "--benchmark_format=json",
         "--benchmark_min_time=0.3"],
        capture_output=True, text=True, check=True).stdout
    return {b["name"]: b["real_time"] for b in json.loads(out)["benchmarks"]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--filter", default="WholeFrame|Stage")
    parser.add_argument("--rounds", type=int, default=6)
    args = parser.parse_args()
    times = {args.old: {}, args.new: {}}
    for _ in range(args.rounds):
        for binary in (args.old, args.new):
            for name, t in run(binary, args.filter).items():
                times[binary].setdefault(name, []).append(t)
    print(f"{'benchmark':40s} {'old min':>8s} {'old med':>8s} {'new min':>8s} {'new med':>8s}"
          f" {'new/old':>8s}")
    for name, old in times[args.old].items():
        new = times[args.new].get(name)
        if not new:
            continue
        ratio = statistics.median(new) / statistics.median(old)
        print(f"{name:40s} {min(old):8.3f} {statistics.median(old):8.3f} {min(new):8.3f}"
              f" {statistics.median(new):8.3f} {ratio:8.3f}")


if __name__ == "__main__":
    main()

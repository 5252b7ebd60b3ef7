#!/usr/bin/env python3
"""ground_truth_resolution.py on a recording with a known turn: 100 deg/s about z, ground truth at
100 Hz, frames at 30 Hz stamped between its poses. An estimate that is the true rotation at each
frame's time is exact against the interpolated ground truth, and off by up to the nearest pose's
0.5 deg against the nearest one."""
import math
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "ground_truth_resolution.py")
RATE_DEG_S = 100.0


def quaternion_z(t):
    half = math.radians(RATE_DEG_S * t) / 2
    return (0.0, 0.0, math.sin(half), math.cos(half))


def pose_line(t):
    qx, qy, qz, qw = quaternion_z(t)
    return f"{t:.6f} 0 0 0 {qx:.9f} {qy:.9f} {qz:.9f} {qw:.9f}\n"


class GroundTruthResolution(unittest.TestCase):
    def test_exact_against_interpolation_off_by_the_pose_spacing_against_nearest(self):
        with tempfile.TemporaryDirectory() as d:
            t0 = 1000.0
            with open(os.path.join(d, "groundtruth.txt"), "w") as f:
                for k in range(400):
                    f.write(pose_line(t0 + 0.01 * k))
            # 30 frames; depth 4 ms after colour; frame times fall between ground-truth poses.
            frames = [t0 + 0.1 + k / 30.0 + 0.0013 * (k % 4) for k in range(30)]
            with open(os.path.join(d, "associations.txt"), "w") as f:
                for t in frames:
                    f.write(f"{t:.6f} rgb/{t:.6f}.png {t + 0.004:.6f} depth/{t + 0.004:.6f}.png\n")
            estimate = os.path.join(d, "estimate.txt")
            with open(estimate, "w") as f:
                for t in frames:
                    f.write(pose_line(t + 0.004))
            out = subprocess.run([sys.executable, SCRIPT, d, estimate], capture_output=True,
                                 text=True, check=True).stdout
        interpolated = [l for l in out.splitlines() if "interpolated ground truth" in l][0]
        nearest = [l for l in out.splitlines() if "nearest      ground truth" in l][0]
        max_of = lambda line: float(line.split("max ")[1].split()[0])
        self.assertLess(max_of(interpolated), 0.01, out)
        self.assertGreater(max_of(nearest), 0.2, out)  # poses 10 ms apart: up to 0.5 deg
        self.assertLessEqual(max_of(nearest), 1.0, out)
        # Colour 4 ms before depth at a constant rate: the same motion between frames.
        stamps = [l for l in out.splitlines() if "depth against colour" in l][0]
        self.assertLess(max_of(stamps), 0.2, out)
        self.assertIn("30 frames", out)


if __name__ == "__main__":
    unittest.main()

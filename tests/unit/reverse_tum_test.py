#!/usr/bin/env python3
"""scripts/reverse_tum.py on a small TUM folder with known stamps: the frames come back in reverse
order with time mirrored about the middle of the depth stamps, each file name still with its own
row's other fields, and the image folders linked."""
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts",
                      "reverse_tum.py")


def rows(path):
    with open(path) as f:
        return [line.split() for line in f if line.strip() and not line.startswith("#")]


class ReverseTum(unittest.TestCase):
    def make_recording(self, d):
        os.makedirs(os.path.join(d, "rgb"))
        os.makedirs(os.path.join(d, "depth"))
        self.depth_t = [100.0, 100.5, 101.25]
        self.rgb_t = [t - 0.01 for t in self.depth_t]
        with open(os.path.join(d, "depth.txt"), "w") as f:
            f.write("# depth maps\n")
            for t in self.depth_t:
                f.write(f"{t:.6f} depth/{t:.6f}.png\n")
        with open(os.path.join(d, "rgb.txt"), "w") as f:
            for t in self.rgb_t:
                f.write(f"{t:.6f} rgb/{t:.6f}.png\n")
        with open(os.path.join(d, "associations.txt"), "w") as f:
            for a, b in zip(self.rgb_t, self.depth_t):
                f.write(f"{a:.6f} rgb/{a:.6f}.png {b:.6f} depth/{b:.6f}.png\n")
        with open(os.path.join(d, "groundtruth.txt"), "w") as f:
            f.write("# timestamp tx ty tz qx qy qz qw\n")
            for k in range(5):
                f.write(f"{99.9 + 0.4 * k:.4f} {k} 0 0 0 0 0 1\n")

    def test_frames_reversed_with_time_mirrored(self):
        with tempfile.TemporaryDirectory() as d:
            src, dst = os.path.join(d, "src"), os.path.join(d, "dst")
            self.make_recording(src)
            subprocess.run([sys.executable, SCRIPT, src, dst], check=True)
            mirror = self.depth_t[0] + self.depth_t[-1]
            depth = rows(os.path.join(dst, "depth.txt"))
            self.assertEqual([r[1] for r in depth],
                             [f"depth/{t:.6f}.png" for t in reversed(self.depth_t)])
            for r in depth:
                original = float(r[1][len("depth/"):-len(".png")])
                self.assertAlmostEqual(float(r[0]), mirror - original, places=6)
            assoc = rows(os.path.join(dst, "associations.txt"))
            self.assertEqual([r[3] for r in assoc], [r[1] for r in depth])
            for r in assoc:  # colour still 10 ms before its depth in the original time
                self.assertAlmostEqual(float(r[0]) - float(r[2]), 0.01, places=6)
            truth = rows(os.path.join(dst, "groundtruth.txt"))
            self.assertEqual([r[1] for r in truth], ["4", "3", "2", "1", "0"])
            self.assertAlmostEqual(float(truth[0][0]), mirror - (99.9 + 1.6), places=6)
            self.assertTrue(os.path.isdir(os.path.join(dst, "rgb")))
            self.assertTrue(os.path.isdir(os.path.join(dst, "depth")))

    def test_a_folder_without_frames_is_an_error(self):
        with tempfile.TemporaryDirectory() as d:
            with open(os.path.join(d, "depth.txt"), "w") as f:
                f.write("# nothing\n")
            done = subprocess.run([sys.executable, SCRIPT, d, os.path.join(d, "out")],
                                  capture_output=True, text=True)
            self.assertNotEqual(done.returncode, 0)
            self.assertIn("lists no frame", done.stderr)

    def test_a_folder_that_is_not_a_recording_is_an_error(self):
        with tempfile.TemporaryDirectory() as d:
            done = subprocess.run([sys.executable, SCRIPT, d, os.path.join(d, "out")],
                                  capture_output=True, text=True)
            self.assertNotEqual(done.returncode, 0)
            self.assertIn("has no depth.txt", done.stderr)


if __name__ == "__main__":
    unittest.main()

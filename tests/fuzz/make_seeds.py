#!/usr/bin/python3
"""Writes the seed corpora of the proto-based fuzz targets (session_config, frame_decode,
frame_pipeline) into tests/fuzz/corpus/. Run once with Debian's python3-grpc-tools; the text
targets' seeds are excerpts of ../shared/data and hand-written camera files."""
import os
import random
import struct
import subprocess
import sys
import tempfile
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def load_proto():
    out = tempfile.mkdtemp()
    subprocess.run([sys.executable, "-m", "grpc_tools.protoc", "-I", os.path.join(ROOT, "proto"),
                    "--python_out", out, "nidevo/v1/odometry.proto"], check=True)
    sys.path.insert(0, out)
    from nidevo.v1 import odometry_pb2
    return odometry_pb2


def png(width, height, bit_depth, colour_type, rows):
    def chunk(kind, body):
        return (struct.pack(">I", len(body)) + kind + body +
                struct.pack(">I", zlib.crc32(kind + body) & 0xffffffff))
    raw = b"".join(b"\x00" + r for r in rows)
    return (b"\x89PNG\r\n\x1a\n" +
            chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, bit_depth, colour_type, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def write(target, name, data):
    folder = os.path.join(HERE, "corpus", target)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data)


def main():
    pb = load_proto()
    config = pb.SessionConfig()
    config.camera.fx, config.camera.fy, config.camera.cx, config.camera.cy = 517.3, 516.5, 318.6, 255.3
    config.camera.width, config.camera.height = 640, 480
    config.camera.distortion.k1, config.camera.distortion.k2 = 0.2624, -0.9531
    config.color_encoding = pb.COLOR_ENCODING_PNG
    config.depth_encoding = pb.DEPTH_ENCODING_PNG16
    config.depth_scale = 5000
    config.overload_policy = pb.OVERLOAD_POLICY_LATEST
    config.queue_capacity = 4
    config.client_name = "seed"
    write("session_config", "tum_png", config.SerializeToString())
    config.color_encoding = pb.COLOR_ENCODING_RGB8
    config.depth_encoding = pb.DEPTH_ENCODING_FLOAT32
    config.camera.ClearField("distortion")
    write("session_config", "raw_float", config.SerializeToString())

    # frame_decode: header (colour enc, depth enc, width - 1, height - 1, depth scale u16 LE).
    w, h = 8, 6
    grey = [bytes((17 * (u + v)) % 256 for u in range(w)) for v in range(h)]
    rgb = [bytes(c for u in range(w) for c in ((3 * u) % 256, (5 * v) % 256, 40)) for v in range(h)]
    depth16 = [b"".join(struct.pack(">H", 5000 + 10 * u + v) for u in range(w)) for v in range(h)]
    header = lambda ce, de: bytes((ce, de, w - 1, h - 1)) + struct.pack("<H", 5000)
    raw_grey = b"".join(grey)
    raw_rgb = b"".join(rgb)
    raw_u16 = b"".join(struct.pack("<H", 5000 + i) for i in range(w * h))
    raw_f32 = b"".join(struct.pack("<f", 1.0 + 0.01 * i) for i in range(w * h))
    cases = {
        "gray8_uint16": (pb.COLOR_ENCODING_GRAY8, pb.DEPTH_ENCODING_UINT16, raw_grey, raw_u16),
        "rgb8_float32": (pb.COLOR_ENCODING_RGB8, pb.DEPTH_ENCODING_FLOAT32, raw_rgb, raw_f32),
        "bgr8_uint16": (pb.COLOR_ENCODING_BGR8, pb.DEPTH_ENCODING_UINT16, raw_rgb, raw_u16),
        "png_png16": (pb.COLOR_ENCODING_PNG, pb.DEPTH_ENCODING_PNG16, png(w, h, 8, 2, rgb),
                      png(w, h, 16, 0, depth16)),
        "pnggrey_float32": (pb.COLOR_ENCODING_PNG, pb.DEPTH_ENCODING_FLOAT32, png(w, h, 8, 0, grey),
                            raw_f32),
    }
    for name, (ce, de, colour, depth) in cases.items():
        frame = pb.Frame(sequence=1, timestamp=0.5, color=colour, depth=depth)
        write("frame_decode", name, header(ce, de) + frame.SerializeToString())

    # frame_pipeline: FuzzedDataProvider input; any bytes drive it, a few lengths seed it.
    rng = random.Random(7)
    for n in (64, 256, 1024):
        write("frame_pipeline", "random_%d" % n, bytes(rng.randrange(256) for _ in range(n)))


if __name__ == "__main__":
    main()

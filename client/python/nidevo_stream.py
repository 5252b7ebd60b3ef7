#!/usr/bin/python3
"""Streams a TUM/ICL-NUIM folder to a nidevo-server and prints one pose per frame.

The colour and depth PNG files go over the wire as they are (COLOR_ENCODING_PNG and
DEPTH_ENCODING_PNG16): the server decodes them. Stubs come from proto/ at run time:

  python3 -m grpc_tools.protoc -Iproto --python_out=OUT --grpc_python_out=OUT \
      proto/nidevo/v1/odometry.proto
  PYTHONPATH=OUT python3 client/python/nidevo_stream.py --target 127.0.0.1:50051 --folder DIR

Output, one line per frame: sequence timestamp status tx ty tz qx qy qz qw psr
(the pose columns follow the TUM trajectory order). Exit code 0 when the stream ends OK.
"""
import argparse
import os
import sys

import grpc

from nidevo.v1 import odometry_pb2 as pb
from nidevo.v1 import odometry_pb2_grpc as pb_grpc


def read_camera(folder):
    """camera.txt: one 'key value' per line (fx fy cx cy width height depth_scale, and
    optionally the lens distortion k1 k2 p1 p2 k3)."""
    camera = {}
    with open(os.path.join(folder, "camera.txt")) as f:
        for number, line in enumerate(f, 1):
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            key, value = line.split()
            camera[key] = float(value)
    missing = {"fx", "fy", "cx", "cy", "width", "height", "depth_scale"} - camera.keys()
    if missing:
        sys.exit(f"{folder}/camera.txt: missing {', '.join(sorted(missing))}")
    return camera


def read_associations(folder):
    """associations.txt: 't_rgb rgb/file t_depth depth/file' per line."""
    frames = []
    with open(os.path.join(folder, "associations.txt")) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            t_rgb, rgb, _t_depth, depth = line.split()[:4]
            frames.append((float(t_rgb), os.path.join(folder, rgb), os.path.join(folder, depth)))
    return frames


def requests(camera, frames):
    config = pb.SessionConfig(
        camera=pb.CameraIntrinsics(
            fx=camera["fx"], fy=camera["fy"], cx=camera["cx"], cy=camera["cy"],
            width=int(camera["width"]), height=int(camera["height"]),
            distortion=pb.LensDistortion(**{k: camera.get(k, 0.0)
                                            for k in ("k1", "k2", "p1", "p2", "k3")})),
        color_encoding=pb.COLOR_ENCODING_PNG,
        depth_encoding=pb.DEPTH_ENCODING_PNG16,
        depth_scale=camera["depth_scale"],
        overload_policy=pb.OVERLOAD_POLICY_BLOCK,
        client_name="nidevo_stream.py")
    yield pb.TrackRequest(config=config)
    for sequence, (timestamp, rgb_path, depth_path) in enumerate(frames):
        with open(rgb_path, "rb") as rgb, open(depth_path, "rb") as depth:
            yield pb.TrackRequest(frame=pb.Frame(sequence=sequence, timestamp=timestamp,
                                                 color=rgb.read(), depth=depth.read()))


def read_token(path):
    """The first token of a token file (one per line, '#' comments), as nidevo-server reads it."""
    with open(path) as f:
        for line in f:
            token = line.split("#", 1)[0].strip()
            if token:
                return token
    raise SystemExit(f"--token_file: {path} holds no token")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--target", default="127.0.0.1:50051")
    parser.add_argument("--folder", required=True, help="TUM folder with camera.txt")
    parser.add_argument("--token_file", default=os.environ.get("NIDEVO_TOKEN_FILE", ""),
                        help="file whose first token is sent as 'authorization: Bearer <token>'")
    args = parser.parse_args()
    metadata = ()
    if args.token_file:
        metadata = (("authorization", "Bearer " + read_token(args.token_file)),)
    camera = read_camera(args.folder)
    frames = read_associations(args.folder)
    with grpc.insecure_channel(args.target) as channel:
        stub = pb_grpc.OdometryServiceStub(channel)
        try:
            for r in stub.Track(requests(camera, frames), metadata=metadata):
                p = r.pose
                status = pb.FrameStatus.Name(r.status).replace("FRAME_STATUS_", "")
                print(f"{r.sequence} {r.timestamp:.6f} {status} {p.tx:.9f} {p.ty:.9f} "
                      f"{p.tz:.9f} {p.qx:.9f} {p.qy:.9f} {p.qz:.9f} {p.qw:.9f} {r.psr:.2f}"
                      + (f"  # {r.reason}" if r.reason else ""))
        except grpc.RpcError as e:
            print(f"stream ended with {e.code().name}: {e.details()}", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

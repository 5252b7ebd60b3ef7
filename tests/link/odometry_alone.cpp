// Links against nidevo_odometry and nothing else of ours (Eigen, FFTW, threads): the method
// must never need the I/O, renderer or evaluation libraries. Tracks a static box corner.
#include <cstdio>

#include "nidevo/odometry/odometry.hpp"

int main() {
  const nidevo::Camera camera = nidevo::Camera{}.subsampled(2);
  nidevo::Odometry odometry(camera, nidevo::OdometryConfig{});
  nidevo::RgbdFrame frame;
  frame.gray.resize(camera.width, camera.height);
  frame.depth.resize(camera.width, camera.height);
  // Three walls of a box corner 2 m away, with a grey ramp for the correlator.
  for (int v = 0; v < camera.height; ++v)
    for (int u = 0; u < camera.width; ++u) {
      frame.depth.at(u, v) = u < camera.width / 2 ? 2.0f + 0.004f * float(u) : 2.5f;
      if (v > camera.height * 2 / 3) frame.depth.at(u, v) = 1.8f;
      frame.gray.at(u, v) = uint8_t((u * 7 + v * 13) % 251);
    }
  nidevo::PoseEstimate pose;
  for (int i = 0; i < 3; ++i) {
    frame.timestamp = i;
    pose = odometry.track(frame);
  }
  const double moved = pose.T_world_cam.translation().norm();
  std::printf("odometry alone: %d frames, last pose %.6f m from the first\n", 3, moved);
  return moved < 0.05 ? 0 : 1;  // a static scene: the pose stays put
}

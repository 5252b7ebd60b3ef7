#pragma once
// Analytic indoor scenes made of textured rectangles (planes and box faces), for ray casting.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "nidevo/sim/texture.hpp"

namespace nidevo::synth {

struct Rect {
  Eigen::Vector3d center;
  Eigen::Vector3d axis_u;  // unit, in-plane
  Eigen::Vector3d axis_v;  // unit, in-plane, orthogonal to axis_u
  Eigen::Vector3d normal;  // unit, axis_u x axis_v
  double half_u = 1.0;
  double half_v = 1.0;
  Eigen::Vector3d tint{1.0, 1.0, 1.0};  // RGB reflectance multiplier
  double albedo = 0.6;                  // mean grey reflectance
  uint32_t texture_seed = 0;
  SurfacePattern pattern = SurfacePattern::kSequence;
  double period = 0.3;  // metres, of the periodic patterns
};

// Where the camera goes: a closed loop of positions and look-at points (world frame, y up).
struct Waypoint {
  Eigen::Vector3d position;
  Eigen::Vector3d look_at;
  // Seconds to the next waypoint; 0: from the sequence's speed and the distances.
  double duration_s = 0;
};

struct Scene {
  std::string name;
  std::vector<Rect> rects;
  std::vector<Waypoint> path;
  Eigen::Vector3d light_dir{0.3, 0.8, 0.5};  // unit after construction
};

// office, corridor, corner, gap (a stretch that looks at a single wall), or random:SEED (a room
// drawn by makeRandomScene).
Scene makeScene(const std::string& name);
// A room of random size and shape with furniture, clutter, posters and mixed surface patterns,
// and a camera path that mixes walking, fast turns, turning on the spot and close looks at one
// wall. Deterministic in the seed.
Scene makeRandomScene(uint64_t seed);
std::vector<std::string> sceneNames();

// Builders used by makeScene, exposed for tests.
Rect makeRect(const Eigen::Vector3d& center, const Eigen::Vector3d& axis_u,
              const Eigen::Vector3d& axis_v, double half_u, double half_v);
// Axis-aligned box rotated by yaw (about world y) then pitch (about the box's x); outward faces.
void addBox(Scene* scene, const Eigen::Vector3d& center, const Eigen::Vector3d& size, double yaw,
            double pitch = 0.0);
// Room interior: six faces with normals pointing inwards.
void addRoom(Scene* scene, const Eigen::Vector3d& min, const Eigen::Vector3d& max);

}  // namespace nidevo::synth

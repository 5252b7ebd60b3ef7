#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "nidevo/sim/scene.hpp"

namespace nidevo::synth {

using Eigen::Vector3d;

namespace {

class Draw {
 public:
  explicit Draw(uint64_t seed) : rng_(seed * 0x9E3779B97F4A7C15ull + 0x1234567ull) {}
  double uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  bool chance(double p) { return uniform(0, 1) < p; }

  // Mixed per surface: rich, near-uniform paint, none, and the periodic patterns.
  void pattern(Rect* r) {
    const double x = uniform(0, 1);
    r->pattern = x < 0.30   ? SurfacePattern::kRich
                 : x < 0.55 ? SurfacePattern::kLow
                 : x < 0.65 ? SurfacePattern::kNone
                 : x < 0.80 ? SurfacePattern::kTiles
                 : x < 0.90 ? SurfacePattern::kStripes
                            : SurfacePattern::kGrid;
    r->period = uniform(0.1, 0.6);
    r->albedo = uniform(0.25, 0.8);
    r->tint = Vector3d(uniform(0.85, 1.0), uniform(0.85, 1.0), uniform(0.85, 1.0));
    r->texture_seed = uint32_t(rng_());
  }

 private:
  std::mt19937_64 rng_;
};

void drawPatterns(Scene* s, size_t first, Draw* draw) {
  for (size_t i = first; i < s->rects.size(); ++i) draw->pattern(&s->rects[i]);
}

// Boxes stand near the walls so that the camera's path through the middle stays free.
void addFurniture(Scene* s, double W, double D, Draw* draw) {
  const int boxes = draw->integer(2, 7);
  for (int b = 0; b < boxes; ++b) {
    const Vector3d size(draw->uniform(0.4, 1.8), draw->uniform(0.4, 2.0), draw->uniform(0.4, 1.2));
    const bool along_x = draw->chance(0.5);
    const double side = draw->chance(0.5) ? 1 : -1;
    Vector3d c = along_x ? Vector3d(draw->uniform(-W / 2 + 0.6, W / 2 - 0.6), size.y() / 2,
                                    side * (D / 2 - draw->uniform(0.4, 1.2)))
                         : Vector3d(side * (W / 2 - draw->uniform(0.4, 1.2)), size.y() / 2,
                                    draw->uniform(-D / 2 + 0.6, D / 2 - 0.6));
    const double pitch = draw->chance(0.2) ? draw->uniform(-0.3, 0.3) : 0.0;
    const size_t first = s->rects.size();
    addBox(s, c, size, draw->uniform(-M_PI, M_PI), pitch);
    drawPatterns(s, first, draw);
  }
}

// Many small surfaces: boxes of 5-30 cm on the floor.
void addClutter(Scene* s, double W, double D, Draw* draw) {
  const int items = draw->integer(5, 20);
  for (int k = 0; k < items; ++k) {
    const Vector3d size(draw->uniform(0.05, 0.3), draw->uniform(0.05, 0.3),
                        draw->uniform(0.05, 0.3));
    const Vector3d c(draw->uniform(-W / 2 + 0.3, W / 2 - 0.3), size.y() / 2,
                     draw->uniform(-D / 2 + 0.3, D / 2 - 0.3));
    const size_t first = s->rects.size();
    addBox(s, c, size, draw->uniform(-M_PI, M_PI),
           draw->chance(0.3) ? draw->uniform(-0.4, 0.4) : 0);
    drawPatterns(s, first, draw);
  }
}

// Posters: thin rich-textured rectangles 1 cm in front of the side walls.
void addPosters(Scene* s, double W, double D, double H, Draw* draw) {
  const int posters = draw->integer(2, 6);
  for (int k = 0; k < posters; ++k) {
    const double side = draw->chance(0.5) ? 1 : -1;
    const double hu = draw->uniform(0.15, 0.6), hv = draw->uniform(0.15, 0.5);
    const double y = draw->uniform(1.0, H - 0.6);
    Rect r = draw->chance(0.5)
                 ? makeRect({side * (W / 2 - 0.01), y, draw->uniform(-D / 2 + 0.8, D / 2 - 0.8)},
                            {0, 0, side}, {0, 1, 0}, hu, hv)
                 : makeRect({draw->uniform(-W / 2 + 0.8, W / 2 - 0.8), y, side * (D / 2 - 0.01)},
                            {-side, 0, 0}, {0, 1, 0}, hu, hv);
    draw->pattern(&r);
    r.pattern = SurfacePattern::kRich;
    s->rects.push_back(r);
  }
}

// A partition wall from one side into the room (both faces) makes an L-shaped space.
void addPartition(Scene* s, double W, double D, double H, Draw* draw) {
  const double z = draw->uniform(-D / 4, D / 4), len = draw->uniform(0.3, 0.6) * W;
  const double side = draw->chance(0.5) ? 1 : -1;
  const double cx = side * (W / 2 - len / 2);
  const size_t first = s->rects.size();
  s->rects.push_back(makeRect({cx, H / 2, z}, {1, 0, 0}, {0, 1, 0}, len / 2, H / 2));
  s->rects.push_back(makeRect({cx, H / 2, z + 0.1}, {-1, 0, 0}, {0, 1, 0}, len / 2, H / 2));
  drawPatterns(s, first, draw);
}

// Segments of four kinds: walking, a fast turn or a turn on the spot, a close look at one wall
// (one large plane), and a look into the far end of the room. Each segment's duration follows
// from a speed of 0.1-1.0 m/s and a rotation rate of 10-90 deg/s, whichever is slower.
void addPath(Scene* s, double W, double D, Draw* draw) {
  const int n = draw->integer(6, 10);
  const double mx = std::max(0.3, W / 2 - 1.4), mz = std::max(0.3, D / 2 - 1.4);
  Vector3d pos(draw->uniform(-mx, mx), draw->uniform(1.2, 1.8), draw->uniform(-mz, mz));
  for (int i = 0; i < n; ++i) {
    Waypoint w;
    const int kind = draw->integer(0, 3);
    if (kind == 0) {  // walk
      pos = Vector3d(draw->uniform(-mx, mx), draw->uniform(1.2, 1.8), draw->uniform(-mz, mz));
    } else if (kind == 1) {  // turn on (nearly) the spot
      pos += Vector3d(draw->uniform(-0.03, 0.03), draw->uniform(-0.03, 0.03),
                      draw->uniform(-0.03, 0.03));
    }
    const double yaw = draw->uniform(-M_PI, M_PI);
    const Vector3d dir(std::sin(yaw), draw->uniform(-0.35, 0.2), std::cos(yaw));
    if (kind == 2) {  // close to a wall, looking at it
      const bool x_wall = draw->chance(0.5);
      const double sgn = draw->chance(0.5) ? 1 : -1, gap = draw->uniform(0.6, 1.2);
      pos = x_wall ? Vector3d(sgn * (W / 2 - gap), draw->uniform(1.2, 1.8), draw->uniform(-mz, mz))
                   : Vector3d(draw->uniform(-mx, mx), draw->uniform(1.2, 1.8), sgn * (D / 2 - gap));
      w.look_at =
          pos + (x_wall ? Vector3d(sgn, draw->uniform(-0.2, 0.2), draw->uniform(-0.2, 0.2))
                        : Vector3d(draw->uniform(-0.2, 0.2), draw->uniform(-0.2, 0.2), sgn));
    } else if (kind == 3) {  // towards the far end
      w.look_at = Vector3d(draw->uniform(-W / 4, W / 4), draw->uniform(0.8, 1.6),
                           pos.z() > 0 ? -D / 2 : D / 2);
    } else {
      w.look_at = pos + 2.0 * dir;
    }
    w.position = pos;
    s->path.push_back(w);
  }
  for (size_t i = 0; i < s->path.size(); ++i) {
    Waypoint& a = s->path[i];
    const Waypoint& b = s->path[(i + 1) % s->path.size()];
    const double dist = (b.position - a.position).norm();
    const Vector3d da = (a.look_at - a.position).normalized(),
                   db = (b.look_at - b.position).normalized();
    const double angle = std::acos(std::clamp(da.dot(db), -1.0, 1.0));
    const double speed = draw->uniform(0.1, 1.0), rate = draw->uniform(10, 90) * M_PI / 180;
    a.duration_s = std::max({dist / speed, angle / rate, 0.3});
  }
}

}  // namespace

Scene makeRandomScene(uint64_t seed) {
  Draw draw(seed);
  Scene s;
  s.name = "random:" + std::to_string(seed);
  const double W = draw.uniform(3, 9), D = draw.uniform(3, 12), H = draw.uniform(2.4, 3.5);
  addRoom(&s, {-W / 2, 0, -D / 2}, {W / 2, H, D / 2});
  drawPatterns(&s, 0, &draw);
  if (draw.chance(0.5)) {  // a tiled floor (the room's face with an upward normal)
    for (Rect& r : s.rects)
      if (r.normal.y() > 0.9) r.pattern = SurfacePattern::kTiles;
  }
  if (draw.chance(0.4)) addPartition(&s, W, D, H, &draw);
  addFurniture(&s, W, D, &draw);
  addClutter(&s, W, D, &draw);
  addPosters(&s, W, D, H, &draw);
  addPath(&s, W, D, &draw);
  s.light_dir = Vector3d(draw.uniform(-0.5, 0.5), 0.8, draw.uniform(-0.5, 0.5)).normalized();
  return s;
}

}  // namespace nidevo::synth

#include "nidevo/sim/scene.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

namespace nidevo::synth {

using Eigen::Vector3d;

Rect makeRect(const Vector3d& center, const Vector3d& axis_u, const Vector3d& axis_v, double half_u,
              double half_v) {
  Rect r;
  r.center = center;
  r.axis_u = axis_u.normalized();
  r.axis_v = axis_v.normalized();
  r.normal = r.axis_u.cross(r.axis_v).normalized();
  r.half_u = half_u;
  r.half_v = half_v;
  return r;
}

namespace {

void addRectTo(Scene* s, Rect r, double albedo, const Vector3d& tint) {
  r.albedo = albedo;
  r.tint = tint;
  r.texture_seed = uint32_t(s->rects.size() * 7919 + 17);
  s->rects.push_back(r);
}

// Every face of a room or box gets a distinct albedo so that plane boundaries stay visible even
// when the texture is switched off.
double faceAlbedo(size_t index) {
  static const double kAlbedo[] = {0.62, 0.48, 0.71, 0.55, 0.40, 0.66, 0.52, 0.58};
  return kAlbedo[index % 8];
}

Vector3d faceTint(size_t index) {
  static const Vector3d kTint[] = {
      {1.0, 0.95, 0.9}, {0.9, 0.95, 1.0}, {0.95, 1.0, 0.9}, {1.0, 0.9, 0.95}, {0.92, 0.92, 1.0}};
  return kTint[index % 5];
}

}  // namespace

void addBox(Scene* s, const Vector3d& center, const Vector3d& size, double yaw, double pitch) {
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(yaw, Vector3d::UnitY()) * Eigen::AngleAxisd(pitch, Vector3d::UnitX()))
          .toRotationMatrix();
  const Vector3d h = size / 2;
  const Vector3d ex = R.col(0), ey = R.col(1), ez = R.col(2);
  // (normal, u, v, half_u, half_v) per face; u x v = outward normal.
  struct Face {
    Vector3d n, u, v;
    double hu, hv, offset;
  };
  const Face faces[] = {{ex, ey, ez, h.y(), h.z(), h.x()}, {-ex, ez, ey, h.z(), h.y(), h.x()},
                        {ey, ez, ex, h.z(), h.x(), h.y()}, {-ey, ex, ez, h.x(), h.z(), h.y()},
                        {ez, ex, ey, h.x(), h.y(), h.z()}, {-ez, ey, ex, h.y(), h.x(), h.z()}};
  for (const auto& f : faces) {
    addRectTo(s, makeRect(center + f.n * f.offset, f.u, f.v, f.hu, f.hv),
              faceAlbedo(s->rects.size()), faceTint(s->rects.size()));
  }
}

void addRoom(Scene* s, const Vector3d& mn, const Vector3d& mx) {
  const Vector3d c = (mn + mx) / 2, h = (mx - mn) / 2;
  const Vector3d X = Vector3d::UnitX(), Y = Vector3d::UnitY(), Z = Vector3d::UnitZ();
  struct Face {
    Vector3d n, u, v;
    double hu, hv, offset;
  };
  // Inward normals: the face at +x has normal -x, and so on.
  const Face faces[] = {{-X, Z, Y, h.z(), h.y(), h.x()}, {X, Y, Z, h.y(), h.z(), h.x()},
                        {-Y, X, Z, h.x(), h.z(), h.y()}, {Y, Z, X, h.z(), h.x(), h.y()},
                        {-Z, Y, X, h.y(), h.x(), h.z()}, {Z, X, Y, h.x(), h.y(), h.z()}};
  for (const auto& f : faces) {
    addRectTo(s, makeRect(c - f.n * f.offset, f.u, f.v, f.hu, f.hv), faceAlbedo(s->rects.size()),
              faceTint(s->rects.size()));
  }
}

namespace {

Scene office() {
  Scene s;
  s.name = "office";
  addRoom(&s, {-3.0, 0.0, -2.5}, {3.0, 2.8, 2.5});
  addBox(&s, {1.6, 0.37, 1.7}, {1.6, 0.74, 0.8}, 0.0);           // desk
  addBox(&s, {1.3, 0.95, 2.1}, {0.55, 0.42, 0.06}, 0.0, -0.25);  // monitor, tilted
  addBox(&s, {-2.5, 0.9, 1.6}, {0.5, 1.8, 0.9}, 0.35);           // cabinet, rotated
  addBox(&s, {-0.5, 1.2, 2.35}, {1.8, 0.04, 0.3}, 0.0);          // shelf boards
  addBox(&s, {-0.5, 1.7, 2.35}, {1.8, 0.04, 0.3}, 0.0);
  addBox(&s, {2.4, 0.45, -1.6}, {0.7, 0.9, 0.7}, -0.6);  // box on the floor
  addBox(&s, {-1.2, 0.25, -1.8}, {0.9, 0.5, 0.5}, 0.25);
  s.path = {{{0.0, 1.45, -0.6}, {1.4, 0.9, 2.5}},   {{0.5, 1.55, -0.3}, {2.6, 1.0, 1.6}},
            {{0.7, 1.5, 0.2}, {3.0, 0.8, -0.6}},    {{0.3, 1.4, 0.4}, {1.6, 0.6, -2.5}},
            {{-0.3, 1.5, 0.3}, {-1.5, 0.7, -2.5}},  {{-0.6, 1.55, 0.0}, {-3.0, 1.0, 0.0}},
            {{-0.4, 1.45, -0.4}, {-2.0, 0.9, 2.5}}, {{-0.2, 1.5, -0.7}, {0.0, 1.2, 2.5}}};
  return s;
}

Scene corridor() {
  Scene s;
  s.name = "corridor";
  addRoom(&s, {-1.0, 0.0, -8.0}, {1.0, 2.6, 8.0});
  addBox(&s, {-0.9, 0.5, -2.0}, {0.2, 1.0, 0.6}, 0.0);  // radiators / cupboards along walls
  addBox(&s, {0.85, 0.9, 0.5}, {0.3, 1.8, 0.8}, 0.0);
  addBox(&s, {-0.88, 1.0, 3.0}, {0.25, 2.0, 0.9}, 0.0);
  addBox(&s, {0.8, 0.3, 4.5}, {0.4, 0.6, 0.5}, 0.3);
  s.path = {{{0.0, 1.5, -5.0}, {0.0, 1.3, 1.0}},    {{0.2, 1.55, -3.0}, {0.4, 1.2, 3.0}},
            {{-0.1, 1.45, -1.0}, {-0.3, 1.3, 5.0}}, {{0.1, 1.5, 1.0}, {0.2, 1.2, 7.0}},
            {{0.0, 1.5, 2.0}, {0.0, 1.3, 8.0}},     {{-0.2, 1.5, 0.0}, {-0.2, 1.2, 6.0}},
            {{0.2, 1.55, -2.0}, {0.3, 1.3, 4.0}},   {{0.0, 1.5, -4.0}, {0.0, 1.3, 2.0}}};
  return s;
}

Scene corner() {
  Scene s;
  s.name = "corner";
  addRoom(&s, {-4.0, 0.0, -4.0}, {4.0, 8.0, 4.0});
  // The camera looks up into the +x/+z corner from head height, so only the two walls show.
  s.path = {{{1.0, 1.6, 1.0}, {4.0, 3.2, 4.0}},
            {{1.4, 1.7, 0.8}, {4.0, 3.4, 3.2}},
            {{1.6, 1.6, 1.3}, {4.0, 3.0, 4.0}},
            {{1.2, 1.5, 1.6}, {3.2, 3.3, 4.0}},
            {{0.9, 1.65, 1.3}, {3.8, 3.4, 4.0}}};
  return s;
}

Scene gap() {
  Scene s;
  s.name = "gap";
  addRoom(&s, {-4.0, 0.0, -4.0}, {4.0, 2.8, 4.0});
  addBox(&s, {2.5, 0.4, 2.8}, {1.0, 0.8, 1.0}, 0.4);
  // Looks into the corner, then turns to face the +z wall square on from close by, so that a
  // single plane fills the view for a while, then turns back.
  s.path = {{{0.6, 1.4, 1.6}, {4.0, 0.9, 4.0}}, {{0.5, 1.4, 2.0}, {2.2, 1.1, 4.0}},
            {{0.2, 1.4, 2.6}, {0.2, 1.4, 4.0}}, {{0.0, 1.4, 2.7}, {0.0, 1.4, 4.0}},
            {{0.3, 1.4, 2.3}, {2.2, 1.1, 4.0}}, {{0.6, 1.4, 1.8}, {4.0, 0.9, 4.0}}};
  return s;
}

// A large hall: walls and ceiling beyond the sensor's range, so the floor is the only large
// plane, and the camera circles a group of furniture-sized objects looking at it (the case of a
// real recording where this odometry was lost on most frames).
Scene hall() {
  Scene s;
  s.name = "hall";
  addRoom(&s, {-12.0, 0.0, -12.0}, {12.0, 10.0, 12.0});
  addBox(&s, {0.0, 0.375, 0.0}, {1.2, 0.75, 0.8}, 0.2);    // table
  addBox(&s, {0.1, 0.87, 0.05}, {0.35, 0.24, 0.3}, -0.5);  // a box on it
  addBox(&s, {-0.9, 0.6, 0.5}, {0.45, 1.2, 0.45}, 0.6);    // a cabinet
  addBox(&s, {0.7, 0.2, -0.8}, {0.5, 0.4, 0.35}, -0.3);    // a crate on the floor
  const Vector3d target(0.0, 0.55, 0.0);
  for (int k = 0; k <= 8; ++k) {
    const double a = 2 * M_PI * k / 8, r = 1.9 + 0.3 * std::sin(3 * a);
    s.path.push_back({{r * std::cos(a), 1.35 + 0.15 * std::cos(2 * a), r * std::sin(a)},
                      target + Vector3d(0.2 * std::sin(a), 0.0, 0.2 * std::cos(a))});
  }
  return s;
}

}  // namespace

std::vector<std::string> sceneNames() { return {"office", "corridor", "corner", "gap", "hall"}; }

Scene makeScene(const std::string& name) {
  Scene s;
  if (name == "office")
    s = office();
  else if (name == "corridor")
    s = corridor();
  else if (name == "corner")
    s = corner();
  else if (name == "gap")
    s = gap();
  else if (name == "hall")
    s = hall();
  else if (name.rfind("random:", 0) == 0 && name.size() > 7 &&
           name.find_first_not_of("0123456789", 7) == std::string::npos)
    s = makeRandomScene(std::stoull(name.substr(7)));
  else
    throw std::invalid_argument("unknown scene '" + name +
                                "' (office, corridor, corner, gap, hall, random:SEED)");
  s.light_dir.normalize();
  return s;
}

}  // namespace nidevo::synth

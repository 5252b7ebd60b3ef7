#pragma once
// Projection of camera-frame points to map pixels in float, one point or four at a time (private
// to the odometry library: the pose check's warp and the plane association share it).
#include <Eigen/Core>
#include <algorithm>

#include "nidevo/odometry/camera.hpp"

namespace nidevo {

// The map camera's intrinsics in float, as the per-point loops use them.
struct Pinhole {
  explicit Pinhole(const Camera& c)
      : fx(float(c.fx)),
        fy(float(c.fy)),
        cx(float(c.cx)),
        cy(float(c.cy)),
        k1(float(c.distortion.k1)),
        k2(float(c.distortion.k2)),
        k3(float(c.distortion.k3)),
        p1(float(c.distortion.p1)),
        p2(float(c.distortion.p2)) {}
  float fx, fy, cx, cy, k1, k2, k3, p1, p2;
};

// Image position of the normalised point (x, y): Brown-Conrady lens, then the pinhole. T is float
// (one point) or Eigen::Array4f (four, vectorised): the same float operations in the same order,
// so both give the same pixels. With all lens coefficients 0 the lens is exactly the identity.
// Always inlined: as an out-of-line call the four-wide version returned its arrays through
// memory (3 % of a frame).
template <typename T>
[[gnu::always_inline]] inline void distortAndProject(const Pinhole& c, const T& x, const T& y, T* u,
                                                     T* v) {
  const T r2 = x * x + y * y;
  const T radial = 1.f + r2 * (c.k1 + r2 * (c.k2 + r2 * c.k3));
  const T xd = x * radial + 2.f * c.p1 * x * y + c.p2 * (r2 + 2.f * x * x);
  const T yd = y * radial + c.p1 * (r2 + 2.f * y * y) + 2.f * c.p2 * x * y;
  *u = c.fx * xd + c.cx;
  *v = c.fy * yd + c.cy;
}

// Points (coordinates X, Y, Z) moved by R and t, and their image positions (u, v). T is float or
// Eigen::Array4f, with the same float operations in the same order, as distortAndProject.
template <typename T>
struct Warped {
  T x, y, z, u, v;
};
inline float atLeast(float a, float b) { return std::max(a, b); }
inline Eigen::Array4f atLeast(const Eigen::Array4f& a, float b) { return a.max(b); }

template <typename T>
[[gnu::always_inline]] inline Warped<T> warpPoint(const Eigen::Matrix3f& R,
                                                  const Eigen::Vector3f& t, const T& X, const T& Y,
                                                  const T& Z, const Pinhole& cam) {
  Warped<T> w;
  w.x = R(0, 0) * X + R(0, 1) * Y + R(0, 2) * Z + t.x();
  w.y = R(1, 0) * X + R(1, 1) * Y + R(1, 2) * Z + t.y();
  w.z = R(2, 0) * X + R(2, 1) * Y + R(2, 2) * Z + t.z();
  const T iz = 1.f / atLeast(w.z, 1e-6f);
  distortAndProject(cam, T(w.x * iz), T(w.y * iz), &w.u, &w.v);
  return w;
}

// Pixel of a point at depth z and image position (u, v), or -1 when it is behind the camera or
// outside the image.
inline int nearestPixel(float z, float u, float v, int width, int height) {
  // Truncation is rounding down once the range test has passed.
  const float ur = u + 0.5f, vr = v + 0.5f;
  const bool inside =
      z > 1e-6f && ur >= 0.f && vr >= 0.f && ur < float(width) && vr < float(height);
  return inside ? int(vr) * width + int(ur) : -1;
}

}  // namespace nidevo

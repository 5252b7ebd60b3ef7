#include "nidevo/odometry/normal_map.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "constant_stride.hpp"
#include "vector_clones.hpp"

// The per-pixel work is done one row at a time by the kernels below. They take planes of floats
// through restrict pointers, compute every pixel and select with masks (no branches), so that
// the compiler vectorises them. Their sums follow Eigen's order (x + (y + z)), which makes the
// results bit for bit those of Vector3f::cross/norm/dot.
namespace nidevo {

namespace {

// Eq. 4 by central differences on the points (ray * z) of rows top, centre and bottom. A pixel
// without depth, a missing neighbour or a depth jump leaves no normal (0 and has = 0), and so do
// the first and last pixels, which lack a neighbour.
NIDEVO_VECTOR_CLONES void centralDifferencesRow(
    const float* __restrict z_top, const float* __restrict z_mid, const float* __restrict z_bot,
    const float* __restrict rx_top, const float* __restrict rx, const float* __restrict rx_bot,
    const float* __restrict ry_top, const float* __restrict ry, const float* __restrict ry_bot,
    int width, float depth_discontinuity, float* __restrict nx, float* __restrict ny,
    float* __restrict nz, uint8_t* __restrict has) {
  for (int u : {0, width - 1}) nx[u] = ny[u] = nz[u] = 0.f, has[u] = 0;
  for (int u = 1; u < width - 1; ++u) {
    const float z0 = z_mid[u], zl = z_mid[u - 1], zr = z_mid[u + 1], zt = z_top[u], zb = z_bot[u];
    const float jump = depth_discontinuity * z0;
    const bool usable = (z0 > 0.f) & (zl > 0.f) & (std::abs(zl - z0) <= jump) & (zr > 0.f) &
                        (std::abs(zr - z0) <= jump) & (zt > 0.f) & (std::abs(zt - z0) <= jump) &
                        (zb > 0.f) & (std::abs(zb - z0) <= jump);
    // a = right - left, b = bottom - top, c = a x b.
    const float ax = rx[u + 1] * zr - rx[u - 1] * zl, ay = ry[u + 1] * zr - ry[u - 1] * zl,
                az = zr - zl;
    const float bx = rx_bot[u] * zb - rx_top[u] * zt, by = ry_bot[u] * zb - ry_top[u] * zt,
                bz = zb - zt;
    float cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
    const float len = std::sqrt(cx * cx + (cy * cy + cz * cz));
    const bool ok = usable & (len > 0.f);
    const float safe_len = ok ? len : 1.f;
    cx /= safe_len;
    cy /= safe_len;
    cz /= safe_len;
    // Towards the camera: flipped when it points along the viewing ray.
    // One factor, +-1 or 0, rather than a choice per component: GCC turns such choices into
    // branches, which stop the vectoriser. c is finite here, so 0 * c is a zero.
    const float facing = cx * (rx[u] * z0) + (cy * (ry[u] * z0) + cz * z0) > 0.f ? -1.f : 1.f;
    const float factor = ok ? facing : 0.f;
    nx[u] = factor * cx;
    ny[u] = factor * cy;
    nz[u] = factor * cz;
    has[u] = ok;
  }
}

// Running box sums of side lo + 1 + hi along one row (missing normals are zero).
void boxSumRow(const float* __restrict in_x, const float* __restrict in_y,
               const float* __restrict in_z, int width, int lo, int hi, float* __restrict out_x,
               float* __restrict out_y, float* __restrict out_z) {
  float ax = 0.f, ay = 0.f, az = 0.f;
  for (int u = 0; u <= std::min(hi, width - 1); ++u) ax += in_x[u], ay += in_y[u], az += in_z[u];
  // The same walk as one loop testing both ends at every pixel, in three spans that need no
  // test (the sums' order, and so their bits, unchanged): only entering, entering and
  // leaving, only leaving.
  const int enter_end = std::min(width, std::max(0, width - hi - 1));  // u + hi + 1 < width
  const int leave_begin = std::min(width, lo);                         // u - lo >= 0
  int u = 0;
  for (; u < std::min(enter_end, leave_begin); ++u) {
    out_x[u] = ax, out_y[u] = ay, out_z[u] = az;
    ax += in_x[u + hi + 1], ay += in_y[u + hi + 1], az += in_z[u + hi + 1];
  }
  for (; u < leave_begin; ++u) out_x[u] = ax, out_y[u] = ay, out_z[u] = az;
  for (; u < enter_end; ++u) {
    out_x[u] = ax, out_y[u] = ay, out_z[u] = az;
    ax += in_x[u + hi + 1], ay += in_y[u + hi + 1], az += in_z[u + hi + 1];
    ax -= in_x[u - lo], ay -= in_y[u - lo], az -= in_z[u - lo];
  }
  for (; u < width; ++u) {
    out_x[u] = ax, out_y[u] = ay, out_z[u] = az;
    ax -= in_x[u - lo], ay -= in_y[u - lo], az -= in_z[u - lo];
  }
}

// sum += in (add) or sum -= in, per component.
NIDEVO_VECTOR_CLONES void accumulateRow(const float* __restrict in_x, const float* __restrict in_y,
                                        const float* __restrict in_z, int width, bool add,
                                        float* __restrict sum_x, float* __restrict sum_y,
                                        float* __restrict sum_z) {
  if (add) {
    for (int u = 0; u < width; ++u) sum_x[u] += in_x[u], sum_y[u] += in_y[u], sum_z[u] += in_z[u];
  } else {
    for (int u = 0; u < width; ++u) sum_x[u] -= in_x[u], sum_y[u] -= in_y[u], sum_z[u] -= in_z[u];
  }
}

// Unit smoothed normal where the pixel had its own normal and the box sum does not vanish.
NIDEVO_VECTOR_CLONES void normaliseRow(const float* __restrict sum_x, const float* __restrict sum_y,
                                       const float* __restrict sum_z, const uint8_t* __restrict has,
                                       int width, float* __restrict nx, float* __restrict ny,
                                       float* __restrict nz, uint8_t* __restrict valid) {
  for (int u = 0; u < width; ++u) {
    const float len = std::sqrt(sum_x[u] * sum_x[u] + (sum_y[u] * sum_y[u] + sum_z[u] * sum_z[u]));
    const bool ok = (has[u] != 0) & (len > 1e-6f);
    const float safe_len = ok ? len : 1.f;
    const float qx = sum_x[u] / safe_len, qy = sum_y[u] / safe_len, qz = sum_z[u] / safe_len;
    nx[u] = ok ? qx : 0.f;
    ny[u] = ok ? qy : 0.f;
    nz[u] = ok ? qz : 0.f;
    valid[u] = ok;
  }
}

// Valid, with every 4-neighbour valid and its normal within crease_dot. Rows are passed as
// (x, y, z, valid) of the row above, this row and the row below.
NIDEVO_VECTOR_CLONES void smoothRow(const float* const* __restrict top,
                                    const float* const* __restrict mid,
                                    const float* const* __restrict bot,
                                    const uint8_t* __restrict valid_top,
                                    const uint8_t* __restrict valid_mid,
                                    const uint8_t* __restrict valid_bot, int width,
                                    float crease_dot, uint8_t* __restrict smooth) {
  const float* __restrict x = mid[0], * __restrict y = mid[1], * __restrict z = mid[2];
  const float* __restrict xt = top[0], * __restrict yt = top[1], * __restrict zt = top[2];
  const float* __restrict xb = bot[0], * __restrict yb = bot[1], * __restrict zb = bot[2];
  for (int u = 1; u < width - 1; ++u) {
    const bool all_valid =
        valid_mid[u] & valid_mid[u - 1] & valid_mid[u + 1] & valid_top[u] & valid_bot[u];
    const float dot_l = x[u] * x[u - 1] + (y[u] * y[u - 1] + z[u] * z[u - 1]);
    const float dot_r = x[u] * x[u + 1] + (y[u] * y[u + 1] + z[u] * z[u + 1]);
    const float dot_t = x[u] * xt[u] + (y[u] * yt[u] + z[u] * zt[u]);
    const float dot_b = x[u] * xb[u] + (y[u] * yb[u] + z[u] * zb[u]);
    smooth[u] = all_valid & (dot_l >= crease_dot) & (dot_r >= crease_dot) & (dot_t >= crease_dot) &
                (dot_b >= crease_dot);
  }
}

}  // namespace

void NormalMap::resize(int w, int h) {
  width = w;
  height = h;
  normal.resize(size_t(w) * size_t(h));
  valid.resize(size_t(w) * size_t(h));
  points.resize(size_t(w) * size_t(h));
  smooth.resize(size_t(w) * size_t(h));
}

int NormalMap::validCount() const {
  int n = 0;
  for (uint8_t v : valid) n += v;
  return n;
}

PixelRays::PixelRays(const Camera& camera, int map_stride) : stride(map_stride) {
  const Camera cam = camera.subsampled(map_stride);
  width = cam.width;
  height = cam.height;
  std::vector<float> column_ray(static_cast<size_t>(width)), row_ray(static_cast<size_t>(height));
  for (int u = 0; u < width; ++u) column_ray[size_t(u)] = float((float(u) - cam.cx) / cam.fx);
  for (int v = 0; v < height; ++v) row_ray[size_t(v)] = float((float(v) - cam.cy) / cam.fy);
  expandRays(cam.distortion, column_ray, row_ray, &x, &y);
}

void NormalMapBuilder::compute(const DepthImageF& depth, const PixelRays& rays, int cell_size,
                               float depth_discontinuity, float min_depth, float max_depth,
                               float crease_dot, NormalMap* out) {
  if (depth.width / rays.stride != rays.width || depth.height / rays.stride != rays.height) {
    throw std::invalid_argument(
        "normal map: depth " + std::to_string(depth.width) + "x" + std::to_string(depth.height) +
        " at stride " + std::to_string(rays.stride) + " gives a " +
        std::to_string(depth.width / rays.stride) + "x" +
        std::to_string(depth.height / rays.stride) + " map, the rays are for " +
        std::to_string(rays.width) + "x" + std::to_string(rays.height));
  }
  const int W = rays.width, H = rays.height;
  const size_t n = size_t(W) * size_t(H);
  out->resize(W, H);
  for (auto* plane : {&z_, &nx_, &ny_, &nz_, &hx_, &hy_, &hz_}) plane->resize(n);
  has_normal_.resize(n);
  backProject(depth, rays, min_depth, max_depth, out);
  rawNormals(rays, depth_discontinuity);
  boxFilter(W, H, cell_size, out);
  markSmooth(W, H, crease_dot, out);
}

float* NormalMapBuilder::rowOf(std::vector<float>& plane, int width, int v) {
  return plane.data() + size_t(v) * size_t(width);
}

const float* NormalMapBuilder::rowOf(const std::vector<float>& plane, int width, int v) {
  return plane.data() + size_t(v) * size_t(width);
}

// Back-projection through the per-pixel rays (Camera::backproject's divisions done once).
void NormalMapBuilder::backProject(const DepthImageF& depth, const PixelRays& rays, float min_depth,
                                   float max_depth, NormalMap* out) {
  const int W = out->width, H = out->height;
  withConstantStride(rays.stride, [&](auto step) {
    for (int v = 0; v < H; ++v) {
      const float* row = &depth.data[size_t(v * step) * size_t(depth.width)];
      float* z_row = rowOf(z_, W, v);
      Eigen::Vector3f* dst = &out->points[size_t(v) * size_t(W)];
      const float* rx = rowOf(rays.x, W, v);
      const float* ry = rowOf(rays.y, W, v);
      for (int u = 0; u < W; ++u) {
        float z = row[u * step];
        if (!(z >= min_depth && z <= max_depth)) z = 0.f;  // also rejects NaN
        z_row[u] = z;
        dst[u] = Eigen::Vector3f(rx[u] * z, ry[u] * z, z);
      }
    }
  });
}

// Paper Eq. 4 at every pixel with both vertical neighbours; the first and last rows get none.
void NormalMapBuilder::rawNormals(const PixelRays& rays, float depth_discontinuity) {
  const int W = rays.width, H = rays.height;
  const std::vector<float>&ray_x = rays.x, &ray_y = rays.y;
  for (int v : {0, H - 1}) {
    std::fill_n(rowOf(nx_, W, v), W, 0.f);
    std::fill_n(rowOf(ny_, W, v), W, 0.f);
    std::fill_n(rowOf(nz_, W, v), W, 0.f);
    std::fill_n(&has_normal_[size_t(v) * size_t(W)], W, uint8_t(0));
  }
  for (int v = 1; v < H - 1; ++v) {
    centralDifferencesRow(rowOf(z_, W, v - 1), rowOf(z_, W, v), rowOf(z_, W, v + 1),
                          rowOf(ray_x, W, v - 1), rowOf(ray_x, W, v), rowOf(ray_x, W, v + 1),
                          rowOf(ray_y, W, v - 1), rowOf(ray_y, W, v), rowOf(ray_y, W, v + 1), W,
                          depth_discontinuity, rowOf(nx_, W, v), rowOf(ny_, W, v), rowOf(nz_, W, v),
                          &has_normal_[size_t(v) * size_t(W)]);
  }
}

// Separable box filter of side cell_size, O(1) per pixel: horizontal sums, then vertical running
// sums walked row by row so that memory is read in order. Only the direction of a sum matters,
// so no count is kept. The smoothed unit normals replace the raw ones in nx_..
void NormalMapBuilder::boxFilter(int W, int H, int cell_size, NormalMap* out) {
  const int lo = cell_size / 2, hi = cell_size - 1 - lo;
  for (int v = 0; v < H; ++v) {
    boxSumRow(rowOf(nx_, W, v), rowOf(ny_, W, v), rowOf(nz_, W, v), W, lo, hi, rowOf(hx_, W, v),
              rowOf(hy_, W, v), rowOf(hz_, W, v));
  }
  sum_x_.assign(size_t(W), 0.f);
  sum_y_.assign(size_t(W), 0.f);
  sum_z_.assign(size_t(W), 0.f);
  auto add_row = [&](int v, bool add) {
    accumulateRow(rowOf(hx_, W, v), rowOf(hy_, W, v), rowOf(hz_, W, v), W, add, sum_x_.data(),
                  sum_y_.data(), sum_z_.data());
  };
  for (int v = 0; v <= std::min(hi, H - 1); ++v) add_row(v, true);
  for (int v = 0; v < H; ++v) {
    const size_t row = size_t(v) * size_t(W);
    normaliseRow(sum_x_.data(), sum_y_.data(), sum_z_.data(), &has_normal_[row], W,
                 rowOf(nx_, W, v), rowOf(ny_, W, v), rowOf(nz_, W, v), &out->valid[row]);
    const float *x = rowOf(nx_, W, v), *y = rowOf(ny_, W, v), *z = rowOf(nz_, W, v);
    Eigen::Vector3f* normal = &out->normal[row];
    for (int u = 0; u < W; ++u) normal[u] = Eigen::Vector3f(x[u], y[u], z[u]);
    if (v + hi + 1 < H) add_row(v + hi + 1, true);
    if (v - lo >= 0) add_row(v - lo, false);
  }
}

// Pixels on a crease (a 4-neighbour normal differs) are useless for plane tracking; marking them
// once here spares stage 2 from doing it for both frames of every pair.
void NormalMapBuilder::markSmooth(int W, int H, float crease_dot, NormalMap* out) {
  std::fill(out->smooth.begin(), out->smooth.end(), uint8_t(0));
  for (int v = 1; v < H - 1; ++v) {
    const float* top[3] = {rowOf(nx_, W, v - 1), rowOf(ny_, W, v - 1), rowOf(nz_, W, v - 1)};
    const float* mid[3] = {rowOf(nx_, W, v), rowOf(ny_, W, v), rowOf(nz_, W, v)};
    const float* bot[3] = {rowOf(nx_, W, v + 1), rowOf(ny_, W, v + 1), rowOf(nz_, W, v + 1)};
    const uint8_t* valid = &out->valid[size_t(v) * size_t(W)];
    smoothRow(top, mid, bot, valid - W, valid, valid + W, W, crease_dot,
              &out->smooth[size_t(v) * size_t(W)]);
  }
}

}  // namespace nidevo

#include "nidevo/odometry/plane_tracking.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "lens_projection.hpp"

namespace nidevo {

PlaneNormalEstimator parsePlaneNormalEstimator(const std::string& name) {
  if (name == "median") return PlaneNormalEstimator::kMedian;
  if (name == "fit") return PlaneNormalEstimator::kPlaneFit;
  throw std::invalid_argument("unknown plane normal estimator '" + name + "' (median, fit)");
}

const char* toString(PlaneNormalEstimator e) {
  return e == PlaneNormalEstimator::kMedian ? "median" : "fit";
}

namespace {

struct Plane {
  Eigen::Vector3f normal;
  Eigen::Vector3f centroid;
};

// Least-squares plane through the points of `pixels`, its normal on the side of the smoothed
// normals (towards the camera).
Plane fitPlane(const NormalMap& map, const int* pixels, size_t count) {
  // Plain scalar sums (the outer product's 6 distinct entries; x*y == y*x exactly): Eigen's
  // Matrix3d accumulator lived on the stack, one store-to-load round trip per pixel.
  double sx = 0, sy = 0, sz = 0, xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
  double nx = 0, ny = 0, nz = 0;
  for (size_t k = 0; k < count; ++k) {
    const Eigen::Vector3f& p = map.points[size_t(pixels[k])];
    const Eigen::Vector3f& n = map.normal[size_t(pixels[k])];
    const double x = p.x(), y = p.y(), z = p.z();
    sx += x, sy += y, sz += z;
    xx += x * x, xy += x * y, xz += x * z, yy += y * y, yz += y * z, zz += z * z;
    nx += double(n.x()), ny += double(n.y()), nz += double(n.z());
  }
  const Eigen::Vector3d sum(sx, sy, sz), mean_normal(nx, ny, nz);
  Eigen::Matrix3d outer;
  outer << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  const Eigen::Vector3d centroid = sum / double(count);
  const Eigen::Matrix3d cov = outer / double(count) - centroid * centroid.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(cov);
  Eigen::Vector3d normal = eig.eigenvectors().col(0);  // smallest eigenvalue
  if (normal.dot(mean_normal) < 0) normal = -normal;
  return {normal.cast<float>(), centroid.cast<float>()};
}

}  // namespace

Eigen::Vector3f PlaneTracker::medianNormal(const NormalMap& map, const int* pixels, size_t count) {
  Eigen::Vector3f r;
  for (int c = 0; c < 3; ++c) {
    for (size_t k = 0; k < count; ++k) scratch_[k] = map.normal[size_t(pixels[k])][c];
    r[c] = kth_smallest_(scratch_.data(), count, count / 2);
  }
  return r.normalized();
}

PlanePair PlaneTracker::fittedPair(const NormalMap& key, const NormalMap& cur, int* key_pixels,
                                   int* cur_pixels, size_t count, const PlaneTrackingParams& p) {
  // A mode holds every surface of one orientation within acos(mode_dot): keep the pixels in a
  // narrow cone around its median orientation, then the dominant offset n.p only (the largest of
  // parallel planes), chosen in the keyframe and used for both frames.
  const Eigen::Vector3f axis = medianNormal(key, key_pixels, count);
  size_t kept = 0;
  auto keep = [&](size_t k) {
    key_pixels[kept] = key_pixels[k];
    cur_pixels[kept++] = cur_pixels[k];
  };
  // The kept pixels' offsets -n.p go to scratch_, so that the histogram and the offset test
  // below do not gather the points again.
  for (size_t k = 0; k < count; ++k) {
    const size_t i = size_t(key_pixels[k]);
    if (key.normal[i].dot(axis) >= p.fit_cone_dot) {
      scratch_[kept] = -axis.dot(key.points[i]);
      keep(k);
    }
  }
  constexpr float kBin = 0.02f;  // metres
  constexpr int kBins = 1024;
  histogram_.assign(kBins, 0);
  for (size_t k = 0; k < kept; ++k)
    ++histogram_[size_t(std::clamp(int(std::floor(scratch_[k] / kBin)), 0, kBins - 1))];
  int peak = 1, best = -1;  // the densest window of three bins
  for (int b = 1; b + 1 < kBins; ++b) {
    const int w = histogram_[size_t(b - 1)] + histogram_[size_t(b)] + histogram_[size_t(b + 1)];
    if (w > best) best = w, peak = b;
  }
  const float d0 = (float(peak) + 0.5f) * kBin, tolerance = 0.05f + 0.03f * d0;
  count = kept;
  kept = 0;
  for (size_t k = 0; k < count; ++k) {
    if (std::abs(scratch_[k] - d0) < tolerance) keep(k);
  }
  count = kept;
  if (count < 3) return {axis, axis, 0};

  // Points of a neighbouring surface whose smoothed normals lean towards this plane (near a
  // shallow crease) pull the fit: refit on the points close to both frames' planes.
  Plane pk = fitPlane(key, key_pixels, count), pc = fitPlane(cur, cur_pixels, count);
  for (int iteration = 0; iteration < 2; ++iteration) {
    for (size_t k = 0; k < count; ++k) {
      const size_t i = size_t(key_pixels[k]), j = size_t(cur_pixels[k]);
      scratch_[k] =
          std::max(std::abs(pk.normal.dot(key.points[i] - pk.centroid)) / key.points[i].z(),
                   std::abs(pc.normal.dot(cur.points[j] - pc.centroid)) / cur.points[j].z());
    }
    std::copy(scratch_.begin(), scratch_.begin() + long(count), residual_.begin());
    const float median = kth_smallest_(residual_.data(), count, count / 2);
    const float limit = std::max(3.f * 1.4826f * median, 1e-4f);
    kept = 0;
    for (size_t k = 0; k < count; ++k)
      if (scratch_[k] <= limit) keep(k);
    if (kept < 3 || kept == count) break;
    count = kept;
    pk = fitPlane(key, key_pixels, count);
    pc = fitPlane(cur, cur_pixels, count);
  }
  return {pk.normal, pc.normal, int(count)};
}

void PlaneTracker::warpPixels(const NormalMap& cur, size_t count, const PlaneWarp& warp,
                              const Pinhole& cam) {
  // Four pixels at a time, in float, as the pose check's warp; the predicted motion is a
  // rotation only.
  using Eigen::Array4f;
  const Eigen::Matrix3f& R = warp.R_key_cur;
  const Eigen::Vector3f no_shift = Eigen::Vector3f::Zero();
  const int* pixels = smooth_row_.data();
  int* out = warped_row_.data();
  size_t j = 0;
  for (; j + 4 <= count; j += 4) {
    Array4f X, Y, Z;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3f& q = cur.points[size_t(pixels[j + size_t(k)])];
      X[k] = q.x(), Y[k] = q.y(), Z[k] = q.z();
    }
    const Warped<Array4f> w = warpPoint(R, no_shift, X, Y, Z, cam);
    for (int k = 0; k < 4; ++k)
      out[j + size_t(k)] = nearestPixel(w.z[k], w.u[k], w.v[k], cur.width, cur.height);
  }
  for (; j < count; ++j) {
    const Eigen::Vector3f& q = cur.points[size_t(pixels[j])];
    const Warped<float> w = warpPoint(R, no_shift, q.x(), q.y(), q.z(), cam);
    out[j] = nearestPixel(w.z, w.u, w.v, cur.width, cur.height);
  }
}

void PlaneTracker::track(const NormalMap& key, const NormalMap& cur, const PlaneTrackingParams& p,
                         PlaneTrackingResult* out, const PlaneWarp* warp) {
  const int W = key.width, H = key.height;
  const size_t n = size_t(W) * size_t(H);
  overlap_pixel_.resize(n);
  overlap_cur_.resize(n);
  overlap_mode_.resize(n);
  members_.resize(n);
  members_cur_.resize(n);
  scratch_.resize(n);
  residual_.resize(n);
  kth_smallest_.reserve(n);
  smooth_row_.resize(size_t(W));
  warped_row_.resize(size_t(W));
  seeds_.resize(size_t(p.max_modes));
  counts_.assign(size_t(p.max_modes) + 1, 0);
  out->overlap_pixels = 0;
  out->planes.clear();

  // Alg. 1: a pixel co-planar in both frames joins the first mode within mode_dot of its
  // keyframe normal, or opens a new one.
  const int border = std::max(p.border, 1);
  int modes = 0;
  size_t overlap = 0;
  const Pinhole cam(warp ? warp->map_camera : Camera{});
  const int step = std::max(p.pixel_step, 1);
  for (int v = border; v < H - border; v += step) {
    // The row's smooth pixels first (branch-free), so that the warp runs on those only, four at
    // a time.
    const size_t row = size_t(v) * size_t(W);
    size_t count = 0;
    for (int u = border; u < W - border; u += step) {
      smooth_row_[count] = int(row) + u;
      count += cur.smooth[row + size_t(u)] != 0;
    }
    if (warp) warpPixels(cur, count, *warp, cam);
    for (size_t j = 0; j < count; ++j) {
      const size_t i = size_t(smooth_row_[j]);
      size_t k = i;
      Eigen::Vector3f nc = cur.normal[i];
      if (warp) {
        const int warped = warped_row_[j];
        if (warped < 0) continue;
        k = size_t(warped);
        nc = warp->R_key_cur * nc;
      }
      if (!key.smooth[k]) continue;
      const Eigen::Vector3f& nk = key.normal[k];
      if (nk.dot(nc) < p.overlap_dot) continue;
      ++out->overlap_pixels;
      int m = 0;
      while (m < modes && nk.dot(seeds_[size_t(m)]) < p.mode_dot) ++m;
      if (m == modes) {
        if (modes == p.max_modes) continue;
        seeds_[size_t(modes++)] = nk;
      }
      overlap_pixel_[overlap] = int(k);
      overlap_cur_[overlap] = int(i);
      overlap_mode_[overlap++] = int8_t(m);
      ++counts_[size_t(m) + 1];
    }
  }
  out->overlap_pixels *= step * step;
  // Group the pixels by mode (counting sort): mode m owns members_[counts_[m] .. counts_[m+1]).
  for (int m = 0; m < modes; ++m) counts_[size_t(m) + 1] += counts_[size_t(m)];
  offsets_.assign(counts_.begin(), counts_.end());
  for (size_t k = 0; k < overlap; ++k) {
    const size_t slot = size_t(offsets_[size_t(overlap_mode_[k])]++);
    members_[slot] = overlap_pixel_[k];
    members_cur_[slot] = overlap_cur_[k];
  }

  for (int m = 0; m < modes; ++m) {
    int* key_pixels = &members_[size_t(counts_[size_t(m)])];
    int* cur_pixels = &members_cur_[size_t(counts_[size_t(m)])];
    const size_t count = size_t(counts_[size_t(m) + 1] - counts_[size_t(m)]);
    if (int(count) < p.min_plane_pixels) continue;
    if (p.estimator == PlaneNormalEstimator::kMedian) {
      out->planes.push_back(
          {medianNormal(key, key_pixels, count), medianNormal(cur, cur_pixels, count), int(count)});
    } else {
      const PlanePair pair = fittedPair(key, cur, key_pixels, cur_pixels, count, p);
      if (pair.pixels >= p.min_plane_pixels) out->planes.push_back(pair);
    }
  }
  std::sort(out->planes.begin(), out->planes.end(),
            [](const PlanePair& a, const PlanePair& b) { return a.pixels > b.pixels; });
}

}  // namespace nidevo

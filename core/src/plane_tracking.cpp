#include "nidevo/plane_tracking.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>

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

bool smoothAround(const NormalMap& m, size_t i, int W, float crease_dot) {
  const Eigen::Vector3f& n = m.normal[i];
  for (size_t j : {i - 1, i + 1, i - size_t(W), i + size_t(W)}) {
    if (!m.valid[j] || n.dot(m.normal[j]) < crease_dot) return false;
  }
  return true;
}

}  // namespace

void PlaneTracker::track(const NormalMap& key, const NormalMap& cur,
                         const PlaneTrackingParams& p, PlaneTrackingResult* out) {
  const int W = key.width, H = key.height;
  const size_t n = size_t(W) * size_t(H);
  mode_of_.assign(n, -1);
  seeds_.resize(size_t(p.max_modes));
  counts_.assign(size_t(p.max_modes), 0);
  scratch_.resize(n);
  members_.resize(n);
  residual_.resize(n);
  out->overlap_pixels = 0;
  out->planes.clear();

  const int border = std::max(p.border, 1);
  int modes = 0;
  for (int v = border; v < H - border; ++v) {
    for (int u = border; u < W - border; ++u) {
      const size_t i = size_t(v) * W + u;
      if (!key.valid[i] || !cur.valid[i]) continue;
      const Eigen::Vector3f& nk = key.normal[i];
      if (nk.dot(cur.normal[i]) < p.overlap_dot) continue;
      if (!smoothAround(key, i, W, p.crease_dot) || !smoothAround(cur, i, W, p.crease_dot)) continue;
      ++out->overlap_pixels;
      int m = 0;
      while (m < modes && nk.dot(seeds_[size_t(m)]) < p.mode_dot) ++m;
      if (m == modes) {
        if (modes == p.max_modes) continue;
        seeds_[size_t(modes++)] = nk;
      }
      mode_of_[i] = int8_t(m);
      ++counts_[size_t(m)];
    }
  }

  // The median of each component, renormalised: robust against the pixels near plane borders.
  auto median_normal = [&](int m, const NormalMap& map) {
    Eigen::Vector3f r;
    for (int c = 0; c < 3; ++c) {
      size_t k = 0;
      for (size_t i = 0; i < n; ++i)
        if (mode_of_[i] == m) scratch_[k++] = map.normal[i][c];
      std::nth_element(scratch_.begin(), scratch_.begin() + long(k / 2), scratch_.begin() + long(k));
      r[c] = scratch_[k / 2];
    }
    return r.normalized();
  };
  // Depth noise averages out of a least-squares plane, while it stays in smoothed normals. A
  // mode holds every surface of one orientation, so the fit keeps the dominant offset n.p only
  // (the largest of parallel planes), chosen in the keyframe and used for both frames.
  struct Plane {
    Eigen::Vector3f normal;
    Eigen::Vector3f centroid;
  };
  auto fit_plane = [&](const NormalMap& map, size_t count) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), mean_normal = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    for (size_t k = 0; k < count; ++k) {
      const Eigen::Vector3d q = map.points[size_t(members_[k])].cast<double>();
      sum += q;
      outer += q * q.transpose();
      mean_normal += map.normal[size_t(members_[k])].cast<double>();
    }
    const Eigen::Vector3d centroid = sum / double(count);
    const Eigen::Matrix3d cov = outer / double(count) - centroid * centroid.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(cov);
    Eigen::Vector3d normal = eig.eigenvectors().col(0);  // smallest eigenvalue
    if (normal.dot(mean_normal) < 0) normal = -normal;
    return Plane{normal.cast<float>(), centroid.cast<float>()};
  };
  // Points of a neighbouring surface whose smoothed normals lean towards this plane (near a
  // shallow crease) pull the fit: refit on the points close to both frames' planes.
  auto robust_fit = [&](size_t count) {
    Plane pk = fit_plane(key, count), pc = fit_plane(cur, count);
    for (int iteration = 0; iteration < 2 && count > 3; ++iteration) {
      for (size_t k = 0; k < count; ++k) {
        const size_t i = size_t(members_[k]);
        scratch_[k] = std::max(std::abs(pk.normal.dot(key.points[i] - pk.centroid)) / key.points[i].z(),
                               std::abs(pc.normal.dot(cur.points[i] - pc.centroid)) / cur.points[i].z());
      }
      std::copy(scratch_.begin(), scratch_.begin() + long(count), residual_.begin());
      std::nth_element(residual_.begin(), residual_.begin() + long(count / 2),
                       residual_.begin() + long(count));
      const float limit = std::max(3.f * 1.4826f * residual_[count / 2], 1e-4f);
      size_t kept = 0;
      for (size_t k = 0; k < count; ++k)
        if (scratch_[k] <= limit) members_[kept++] = members_[k];
      if (kept < 3 || kept == count) break;
      count = kept;
      pk = fit_plane(key, count);
      pc = fit_plane(cur, count);
    }
    return std::make_tuple(pk.normal, pc.normal, int(count));
  };
  auto fitted_pair = [&](int m) {
    // Members within a narrow cone around the mode's median orientation only: a mode may hold
    // surfaces up to acos(mode_dot) apart.
    const Eigen::Vector3f seed = median_normal(m, key);
    auto in_cone = [&](size_t i) { return key.normal[i].dot(seed) >= p.fit_cone_dot; };
    constexpr float kBin = 0.02f;  // metres
    constexpr int kBins = 1024;
    offset_histogram_.assign(kBins, 0);
    for (size_t i = 0; i < n; ++i) {
      if (mode_of_[i] != m || !in_cone(i)) continue;
      const int b = std::clamp(int(std::floor(-seed.dot(key.points[i]) / kBin)), 0, kBins - 1);
      ++offset_histogram_[size_t(b)];
    }
    int peak = 0;  // the densest 3-bin window
    for (int b = 1; b + 1 < kBins; ++b) {
      const int w = offset_histogram_[size_t(b - 1)] + offset_histogram_[size_t(b)] +
                    offset_histogram_[size_t(b + 1)];
      const int best = offset_histogram_[size_t(std::max(peak - 1, 0))] +
                       offset_histogram_[size_t(peak)] + offset_histogram_[size_t(peak + 1)];
      if (w > best) peak = b;
    }
    const float d0 = (float(peak) + 0.5f) * kBin, tolerance = 0.05f + 0.03f * d0;
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) {
      if (mode_of_[i] == m && in_cone(i) && std::abs(-seed.dot(key.points[i]) - d0) < tolerance) {
        members_[count++] = int(i);
      }
    }
    if (count < 3) return PlanePair{seed, seed, 0};
    const auto [nk, nc, kept] = robust_fit(count);
    return PlanePair{nk, nc, kept};
  };
  for (int m = 0; m < modes; ++m) {
    if (counts_[size_t(m)] < p.min_plane_pixels) continue;
    if (p.estimator == PlaneNormalEstimator::kMedian) {
      out->planes.push_back({median_normal(m, key), median_normal(m, cur), counts_[size_t(m)]});
    } else {
      const PlanePair pair = fitted_pair(m);
      if (pair.pixels >= p.min_plane_pixels) out->planes.push_back(pair);
    }
  }
  std::sort(out->planes.begin(), out->planes.end(),
            [](const PlanePair& a, const PlanePair& b) { return a.pixels > b.pixels; });
}

}  // namespace nidevo

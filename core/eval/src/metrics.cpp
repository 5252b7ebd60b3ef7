#include "nidevo/eval/metrics.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>

#include "nidevo/io/dataset.hpp"

namespace nidevo {

ErrorStatistics computeStatistics(std::vector<double> e) {
  ErrorStatistics s;
  s.count = e.size();
  if (e.empty()) return s;
  double sum = 0, sse = 0;
  for (double x : e) {
    sum += x;
    sse += x * x;
  }
  const double n = double(e.size());
  s.mean = sum / n;
  s.sse = sse;
  s.rmse = std::sqrt(sse / n);
  double var = 0;
  for (double x : e) var += (x - s.mean) * (x - s.mean);
  s.std = std::sqrt(var / n);  // population std, as numpy/evo
  auto [mn, mx] = std::minmax_element(e.begin(), e.end());
  s.min = *mn;
  s.max = *mx;
  std::sort(e.begin(), e.end());
  const size_t m = e.size() / 2;
  s.median = e.size() % 2 ? e[m] : 0.5 * (e[m - 1] + e[m]);
  return s;
}

MatchedTrajectories matchByTimestamp(const Trajectory& estimate, const Trajectory& reference,
                                     double max_difference, double estimate_offset_s) {
  std::vector<double> ta, tb;
  for (auto& p : estimate) ta.push_back(p.timestamp + estimate_offset_s);
  for (auto& p : reference) tb.push_back(p.timestamp);
  MatchedTrajectories m;
  for (auto [i, j] : associateByTimestamp(ta, tb, max_difference)) {
    m.estimate.push_back(estimate[i].pose());
    m.reference.push_back(reference[j].pose());
    m.timestamps.push_back(estimate[i].timestamp);
  }
  return m;
}

AteResult computeAte(const MatchedTrajectories& m) {
  const size_t n = m.estimate.size();
  if (n < 3) {
    throw std::invalid_argument("ATE needs at least 3 matched poses, got " + std::to_string(n));
  }
  Eigen::Matrix3Xd src(3, n), dst(3, n);
  for (size_t i = 0; i < n; ++i) {
    src.col(Eigen::Index(i)) = m.estimate[i].translation();
    dst.col(Eigen::Index(i)) = m.reference[i].translation();
  }
  AteResult r;
  r.alignment = Eigen::Isometry3d(Eigen::umeyama(src, dst, /*with_scaling=*/false));
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d a = r.alignment * m.estimate[i].translation();
    r.aligned_estimate.push_back(a);
    r.reference.push_back(m.reference[i].translation());
    r.errors.push_back((a - m.reference[i].translation()).norm());
  }
  r.translation = computeStatistics(r.errors);
  return r;
}

RpeResult computeRpe(const MatchedTrajectories& m, int delta) {
  if (delta < 1) throw std::invalid_argument("RPE delta must be at least 1 frame");
  std::vector<double> et, er;
  for (size_t i = 0; i + size_t(delta) < m.estimate.size(); ++i) {
    const size_t j = i + size_t(delta);
    const Eigen::Isometry3d ref_rel = m.reference[i].inverse() * m.reference[j];
    const Eigen::Isometry3d est_rel = m.estimate[i].inverse() * m.estimate[j];
    const Eigen::Isometry3d err = ref_rel.inverse() * est_rel;
    et.push_back(err.translation().norm());
    er.push_back(Eigen::AngleAxisd(err.rotation()).angle() * 180.0 / M_PI);
  }
  return {computeStatistics(et), computeStatistics(er)};
}

namespace {

// The reference pose nearest in time to t within max_difference (reference sorted by time).
const StampedPose* nearestPose(const Trajectory& reference, double t, double max_difference) {
  auto it = std::lower_bound(reference.begin(), reference.end(), t,
                             [](const StampedPose& p, double x) { return p.timestamp < x; });
  const StampedPose* best = nullptr;
  for (auto c : {it, it == reference.begin() ? it : std::prev(it)}) {
    if (c == reference.end()) continue;
    const double d = std::abs(c->timestamp - t);
    if (d <= max_difference && (!best || d < std::abs(best->timestamp - t))) best = &*c;
  }
  return best;
}

}  // namespace

std::vector<FrameError> frameToFrameErrors(const Trajectory& estimate, const Trajectory& reference,
                                           double max_difference) {
  std::vector<FrameError> out(estimate.size());
  for (size_t i = 1; i < estimate.size(); ++i) {
    const StampedPose* r0 = nearestPose(reference, estimate[i - 1].timestamp, max_difference);
    const StampedPose* r1 = nearestPose(reference, estimate[i].timestamp, max_difference);
    if (!r0 || !r1) continue;
    const Eigen::Isometry3d ref_rel = r0->pose().inverse() * r1->pose();
    const Eigen::Isometry3d est_rel = estimate[i - 1].pose().inverse() * estimate[i].pose();
    const Eigen::Isometry3d err = ref_rel.inverse() * est_rel;
    out[i].judged = true;
    out[i].rotation_deg = Eigen::AngleAxisd(err.rotation()).angle() * 180.0 / M_PI;
    out[i].translation_m = err.translation().norm();
  }
  return out;
}

SilentFailures countSilentFailures(const Trajectory& estimate,
                                   const std::vector<bool>& reported_good,
                                   const Trajectory& reference, double max_rotation_deg,
                                   double max_translation_m, double max_difference) {
  if (reported_good.size() != estimate.size())
    throw std::invalid_argument("countSilentFailures: one good flag per estimated pose needed");
  const std::vector<FrameError> errors = frameToFrameErrors(estimate, reference, max_difference);
  SilentFailures out;
  for (size_t i = 0; i < estimate.size(); ++i) {
    if (!reported_good[i] || !errors[i].judged) continue;
    ++out.judged;
    if (errors[i].rotation_deg > max_rotation_deg || errors[i].translation_m > max_translation_m) {
      ++out.count;
      out.timestamps.push_back(estimate[i].timestamp);
    }
  }
  return out;
}

std::string formatStatisticsTable(const std::string& title, const ErrorStatistics& s,
                                  const std::string& unit) {
  char buf[512];
  std::snprintf(buf, sizeof(buf),
                "%s (%s, %zu poses)\n"
                "       max\t%.6f\n      mean\t%.6f\n    median\t%.6f\n       min\t%.6f\n"
                "      rmse\t%.6f\n       sse\t%.6f\n       std\t%.6f\n",
                title.c_str(), unit.c_str(), s.count, s.max, s.mean, s.median, s.min, s.rmse, s.sse,
                s.std);
  return buf;
}

}  // namespace nidevo

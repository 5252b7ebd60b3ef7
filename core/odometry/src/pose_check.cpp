#include "nidevo/odometry/pose_check.hpp"

#include <algorithm>
#include <cmath>

namespace nidevo {

CheckVerdict judgeAlignment(const AlignmentResult& a, const OdometryConfig& c) {
  if (a.overlapFraction() < c.verify_min_overlap)
    return {false, "pose failed verification: too little of the reference frame in view"};
  if (a.inlierFraction() < c.verify_min_inliers)
    return {false, "pose failed verification: depth disagrees with the pose"};
  if (a.rms_m > c.verify_max_rms_m)
    return {false, "pose failed verification: surface residual too large"};
  if (a.ref_intensity_std >= c.verify_texture_std && a.ncc < c.verify_min_ncc)
    return {false, "pose failed verification: grey values disagree with the pose"};
  return {true, ""};
}

double alignmentScore(const AlignmentResult& a, const OdometryConfig& c) {
  const double ncc = a.ref_intensity_std >= c.verify_texture_std ? std::clamp(a.ncc, 0.0, 1.0) : 0;
  return a.inliers * (1.0 + 0.5 * ncc);
}

double priorDistance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                     const OdometryConfig& c) {
  const Eigen::Isometry3d d = a.inverse() * b;
  return d.translation().norm() / c.prior_translation_m +
         Eigen::AngleAxisd(d.rotation()).angle() / c.prior_rotation_rad;
}

bool farApart(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, const OdometryConfig& c) {
  return priorDistance(a, b, c) > 1.0;
}

bool distinctTie(const AlignmentResult& a, const AlignmentResult& b, const OdometryConfig& c) {
  const double sa = alignmentScore(a, c), sb = alignmentScore(b, c);
  return std::abs(sa - sb) <= c.hypothesis_tie * std::max(sa, sb) &&
         farApart(a.T_ref_cur, b.T_ref_cur, c);
}

bool directionsTrusted(const AlignmentResult& best, const Eigen::Isometry3d& T_ref_predicted,
                       const HypothesisOrigin& origin, const OdometryConfig& c) {
  if (best.depth_constrained == 6) return true;
  if (farApart(best.T_ref_cur, T_ref_predicted, c)) return false;
  const bool grey_fixed_some = best.constrained > best.depth_constrained;
  const bool grey_fixes_count =
      !grey_fixed_some || !c.grey_fixed_needs_ncc || best.ncc >= c.verify_min_ncc;
  if (best.constrained + best.confirmed == 6 && grey_fixes_count) return true;
  return origin.from_method && (!best.free_rotation || origin.rotation_measured) &&
         (!best.free_translation || origin.translation_measured);
}

bool freeAlongKccRidge(const AlignmentResult& best, const KccRidges& ridges) {
  for (int k = 0; k < best.weak_count; ++k) {
    const Eigen::Vector3d translation = best.weak_axes.col(k).tail<3>();
    for (int a = 0; a < ridges.count; ++a)
      if (std::abs(translation.dot(ridges.axis[a])) > 0.5) return true;
  }
  return false;
}

void PredictionRecord::verified(const Eigen::Isometry3d& T_predicted,
                                const Eigen::Isometry3d& T_verified) {
  const Eigen::Isometry3d d = T_predicted.inverse() * T_verified;
  angle_rad_[size_t(next_)] = float(Eigen::AngleAxisd(d.rotation()).angle());
  distance_m_[size_t(next_)] = float(d.translation().norm());
  next_ = (next_ + 1) % kMaxFrames;
  count_ = std::min(count_ + 1, kMaxFrames);
  frames_since_verified_ = 0;
}

bool PredictionRecord::reliable(const OdometryConfig& c) const {
  const int n = c.prediction_trust_frames;
  if (n <= 0 || count_ < n || frames_since_verified_ + 1 > c.prediction_trust_gap) return false;
  float angle_sq = 0, distance_sq = 0;
  for (int k = 1; k <= n; ++k) {
    const size_t i = size_t((next_ - k + kMaxFrames) % kMaxFrames);
    angle_sq += angle_rad_[i] * angle_rad_[i];
    distance_sq += distance_m_[i] * distance_m_[i];
  }
  return std::sqrt(angle_sq / float(n)) <= c.prediction_trust_rad &&
         std::sqrt(distance_sq / float(n)) <= c.prediction_trust_m;
}

bool withinPredictionTrust(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                           const OdometryConfig& c) {
  const Eigen::Isometry3d d = a.inverse() * b;
  return Eigen::AngleAxisd(d.rotation()).angle() <= c.prediction_trust_rad &&
         d.translation().norm() <= c.prediction_trust_m;
}

HypothesisChoice chooseHypothesis(const AlignmentResult* results, const CheckVerdict* verdicts,
                                  const HypothesisOrigin* origins, int count,
                                  const Eigen::Isometry3d& T_ref_predicted,
                                  const OdometryConfig& c) {
  int chosen = 0;
  for (int h = 1; h < count; ++h) {
    const bool passes = verdicts[h].passed, best_passes = verdicts[chosen].passed;
    if (passes != best_passes) {
      if (passes) chosen = h;
      continue;
    }
    // Within a tie, poses close together are one solution (the better converged wins); poses
    // far apart are distinct solutions, and the prediction decides.
    if (distinctTie(results[h], results[chosen], c)
            ? priorDistance(results[h].T_ref_cur, T_ref_predicted, c) <
                  priorDistance(results[chosen].T_ref_cur, T_ref_predicted, c)
            : alignmentScore(results[h], c) > alignmentScore(results[chosen], c))
      chosen = h;
  }
  HypothesisChoice choice{chosen, false};
  if (!verdicts[chosen].passed) return choice;
  for (int h = 0; h < count; ++h)
    if (h != chosen && verdicts[h].passed)
      choice.ambiguous |= distinctTie(results[h], results[chosen], c);
  // Along a direction only grey values fix, a better fit far from the prediction is no proof: a
  // periodic texture fits nearly as well a period away.
  auto trusted = [&](int h) {
    return directionsTrusted(results[h], T_ref_predicted, origins[h], c);
  };
  if (trusted(chosen)) return choice;
  int alternative = -1;
  for (int h = 0; h < count; ++h) {
    if (h == chosen || !verdicts[h].passed || !trusted(h)) continue;
    if (alternative < 0 || alignmentScore(results[h], c) > alignmentScore(results[alternative], c))
      alternative = h;
  }
  if (alternative >= 0) return {alternative, true, true};
  // No trusted alternative: a pose far from the prediction that fits no more of the surface than
  // one near it owes its lead to grey values alone, along a direction the geometry leaves free
  // (a KCC peak on the wrong texture); the pose near the prediction is the better guess.
  if (!farApart(results[chosen].T_ref_cur, T_ref_predicted, c)) return choice;
  int nearest = -1;
  for (int h = 0; h < count; ++h) {
    if (h == chosen || farApart(results[h].T_ref_cur, T_ref_predicted, c) ||
        results[h].inliers < results[chosen].inliers)
      continue;
    if (nearest < 0 || priorDistance(results[h].T_ref_cur, T_ref_predicted, c) <
                           priorDistance(results[nearest].T_ref_cur, T_ref_predicted, c))
      nearest = h;
  }
  if (nearest >= 0) choice = {nearest, true, true};
  return choice;
}

bool tieBeyondOkBounds(const AlignmentResult* results, const CheckVerdict* verdicts, int count,
                       int chosen, const OdometryConfig& c) {
  const double chosen_score = alignmentScore(results[chosen], c);
  for (int h = 0; h < count; ++h) {
    if (h == chosen || !verdicts[h].passed) continue;
    const double score = alignmentScore(results[h], c);
    if (std::abs(score - chosen_score) <= c.hypothesis_tie * std::max(score, chosen_score) &&
        !withinPredictionTrust(results[h].T_ref_cur, results[chosen].T_ref_cur, c))
      return true;
  }
  return false;
}

StatusDecision decideStatus(const StatusEvidence& e, const OdometryConfig& c) {
  StatusDecision d;
  const auto degraded = [&d](const char* reason) {
    d.ok = false;
    d.reason = reason;
    return d;
  };
  if (!e.verdict.passed) return degraded(e.verdict.reason);
  const bool prediction_vouches =
      e.prediction_reliable && withinPredictionTrust(e.best->T_ref_cur, e.T_ref_predicted, c);
  if (e.choice.overruled || e.choice.ambiguous) {
    if (c.prediction_settles_ties && prediction_vouches) {
      d.predicted_directions = true;
      d.tie_settled = true;
      return d;
    }
    return degraded(e.choice.overruled
                        ? "a better fit far from the prediction rests on grey values alone (a "
                          "periodic pattern?); the pose near the prediction kept"
                        : "two poses fit equally (a periodic pattern?); the one nearer the "
                          "prediction kept");
  }
  // Along a direction the geometry leaves free the pose is the hypothesis': trusted only when
  // that is the method's own, and the method measured that kind of motion; not where the KCC's
  // response was a ridge along it (a bare wall slides along it in the projection).
  const bool kcc_ridge_free = e.origin.from_method && freeAlongKccRidge(*e.best, e.ridges);
  if (!kcc_ridge_free && directionsTrusted(*e.best, e.T_ref_predicted, e.origin, c)) return d;
  // The free direction holds the hypothesis' value: as good as the prediction when it agrees
  // with a prediction that has been right lately.
  if (prediction_vouches) {
    d.predicted_directions = true;
    return d;
  }
  return degraded(e.method_problem ? e.method_problem
                  : kcc_ridge_free
                      ? "geometry leaves a direction unverified that the KCC did not measure (its "
                        "response is a ridge along it)"
                      : "geometry leaves a direction unverified");
}

}  // namespace nidevo

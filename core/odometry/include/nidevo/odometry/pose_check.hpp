#pragma once
// The pose check's rules (stage 3's last step), apart from the state they run on: whether an
// alignment passes, how two hypotheses compare, and whether a passing pose may be called OK.
#include <Eigen/Geometry>
#include <array>

#include "nidevo/odometry/depth_alignment.hpp"
#include "nidevo/odometry/odometry_config.hpp"

namespace nidevo {

struct CheckVerdict {
  bool passed = false;
  const char* reason = "";  // static text; empty when passed
};
CheckVerdict judgeAlignment(const AlignmentResult& a, const OdometryConfig& c);

// More agreeing points first; on texture, grey-value agreement breaks near-ties.
double alignmentScore(const AlignmentResult& a, const OdometryConfig& c);

// Motion between two poses in units of the prior: translation over prior_translation_m plus
// rotation over prior_rotation_rad. Beyond 1 the poses are far apart.
double priorDistance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                     const OdometryConfig& c);
bool farApart(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, const OdometryConfig& c);

// Two fits within hypothesis_tie of each other at poses far apart: distinct solutions that the
// data cannot tell apart (a periodic texture fits as well one period away).
bool distinctTie(const AlignmentResult& a, const AlignmentResult& b, const OdometryConfig& c);

// What is known of the chosen hypothesis besides its alignment.
struct HypothesisOrigin {
  bool from_method = false;           // the method's own pose (not the prediction or last pose)
  bool rotation_measured = false;     // from two planes
  bool translation_measured = false;  // from a confident, unrivalled KCC match
};

// Translation axes (unit, in the current camera's frame) along which the KCC response was a
// ridge (KccMatch::ridge_u, ridge_v): the method did not measure the translation along them.
struct KccRidges {
  int count = 0;
  Eigen::Vector3d axis[2];
};

// Whether a direction the alignment left free (AlignmentResult::weak_axes) translates mostly
// along a ridge axis: there the pose holds the KCC's value, and the KCC had none to give.
bool freeAlongKccRidge(const AlignmentResult& best, const KccRidges& ridges);

// Whether a passing alignment's pose is right in every direction. Depth fixes a direction for
// certain; grey values may fix it a texture period away, a weak direction the data confirmed
// (AlignmentResult::confirmed) may be an alias too, and a direction left free has only the
// method's word: all three are trusted near the prediction (T_ref_predicted) only.
bool directionsTrusted(const AlignmentResult& best, const Eigen::Isometry3d& T_ref_predicted,
                       const HypothesisOrigin& origin, const OdometryConfig& c);

// The motion prediction's error on the recent verified frames (verified: OK with every direction
// fixed by the data or the method's measurement, not by the prediction itself).
class PredictionRecord {
 public:
  static constexpr int kMaxFrames = 16;  // bounds OdometryConfig::prediction_trust_frames
  void verified(const Eigen::Isometry3d& T_predicted, const Eigen::Isometry3d& T_verified);
  void unverified() { ++frames_since_verified_; }
  // Whether the prediction's RMS error (rotation and translation apart) over the last
  // prediction_trust_frames verified frames, the latest at most prediction_trust_gap frames
  // back, is within prediction_trust_rad and prediction_trust_m.
  bool reliable(const OdometryConfig& c) const;

 private:
  std::array<float, kMaxFrames> angle_rad_{}, distance_m_{};  // a ring, next_ the oldest
  int count_ = 0, next_ = 0;
  int frames_since_verified_ = 0;
};

// Whether two poses differ by at most prediction_trust_rad and prediction_trust_m.
bool withinPredictionTrust(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                           const OdometryConfig& c);

// Which of `count` checked hypotheses (the method's first) gives the pose. A passing one beats a
// failing one; among passing ones the best fit wins, except that fits within hypothesis_tie at
// poses far apart are a tie won by the pose nearer the prediction, and a pose that cannot be
// trusted (directionsTrusted) loses to a passing one that can. Both of those make the frame
// ambiguous: the data alone could not decide. Failing that, an untrusted pose far from the
// prediction loses to a hypothesis near it that fits at least as many surface points, passed or
// not (the lead was the grey values' along a free direction); the frame is overruled.
struct HypothesisChoice {
  int index = 0;
  bool ambiguous = false;
  bool overruled = false;  // the best fit could not be trusted, and another was taken
};
HypothesisChoice chooseHypothesis(const AlignmentResult* results, const CheckVerdict* verdicts,
                                  const HypothesisOrigin* origins, int count,
                                  const Eigen::Isometry3d& T_ref_predicted,
                                  const OdometryConfig& c);

// Whether a passing hypothesis other than `chosen` fits within hypothesis_tie of it (the
// alignment score) yet ends further from it than OK promises (withinPredictionTrust): the data
// could not tell the two poses apart, and they differ by more than an OK pose may be off.
bool tieBeyondOkBounds(const AlignmentResult* results, const CheckVerdict* verdicts, int count,
                       int chosen, const OdometryConfig& c);

// What the check found for a frame, as the status rules read it.
struct StatusEvidence {
  const AlignmentResult* best = nullptr;  // the chosen hypothesis' alignment
  CheckVerdict verdict;
  HypothesisChoice choice;
  HypothesisOrigin origin;
  Eigen::Isometry3d T_ref_predicted = Eigen::Isometry3d::Identity();
  KccRidges ridges;
  bool prediction_reliable = false;      // PredictionRecord::reliable
  const char* method_problem = nullptr;  // why the method's own estimate is weak, or nullptr
};
// The status a checked pose earns. Not OK: why (static text). OK with predicted_directions: a
// direction holds the prediction's value (it vouches for it: reliable, and the pose within its
// bounds). tie_settled: a periodic pattern's tie the prediction settled. No rule moves the pose.
struct StatusDecision {
  bool ok = true;
  const char* reason = "";
  bool predicted_directions = false;
  bool tie_settled = false;
};
StatusDecision decideStatus(const StatusEvidence& e, const OdometryConfig& c);

}  // namespace nidevo

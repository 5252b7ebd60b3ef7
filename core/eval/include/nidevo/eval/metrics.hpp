#pragma once
// Trajectory metrics as the evo toolbox reports them: ATE after a rigid (no scale) alignment and
// RPE over a frame delta.
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "nidevo/io/trajectory.hpp"

namespace nidevo {

struct ErrorStatistics {
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0, sse = 0;
  size_t count = 0;
};
ErrorStatistics computeStatistics(std::vector<double> errors);

// Estimate and reference poses matched by timestamp (within max_difference seconds), the
// estimate's timestamps shifted by estimate_offset_s first (TUM's evaluate_ate.py --offset): a
// sensor whose stamps lag its capture by L matches the reference best at -L.
struct MatchedTrajectories {
  std::vector<Eigen::Isometry3d> estimate;
  std::vector<Eigen::Isometry3d> reference;
  std::vector<double> timestamps;
};
MatchedTrajectories matchByTimestamp(const Trajectory& estimate, const Trajectory& reference,
                                     double max_difference = 0.01, double estimate_offset_s = 0.0);

struct AteResult {
  ErrorStatistics translation;  // metres
  Eigen::Isometry3d alignment;  // applied to the estimate: reference ~ alignment * estimate
  std::vector<Eigen::Vector3d> aligned_estimate;
  std::vector<Eigen::Vector3d> reference;
  std::vector<double> errors;
};
// Throws std::invalid_argument if fewer than 3 poses match.
AteResult computeAte(const MatchedTrajectories& matched);

struct RpeResult {
  ErrorStatistics translation;  // metres
  ErrorStatistics rotation;     // degrees
};
// Relative error between frames i and i + delta (evo's RPE with delta in frames).
RpeResult computeRpe(const MatchedTrajectories& matched, int delta = 1);

// Frame i's motion since frame i-1 against the reference's; frame 0, and frames without a
// reference pose within max_difference seconds (theirs or the previous frame's), are not judged.
struct FrameError {
  bool judged = false;
  double rotation_deg = 0;
  double translation_m = 0;
};
std::vector<FrameError> frameToFrameErrors(const Trajectory& estimate, const Trajectory& reference,
                                           double max_difference = 0.01);

// Frames a method reported as good whose motion since the previous frame is wrong by more than
// the bounds against the reference: the failures nobody was told about. Frame i is judged when
// frames i-1 and i both match a reference pose within max_difference seconds.
struct SilentFailures {
  int count = 0;                   // judged, reported good, and wrong
  int judged = 0;                  // judged and reported good
  std::vector<double> timestamps;  // of the silent failures
};
// `reported_good[i]` says whether the method called estimate[i] good (OK).
SilentFailures countSilentFailures(const Trajectory& estimate,
                                   const std::vector<bool>& reported_good,
                                   const Trajectory& reference, double max_rotation_deg = 2.0,
                                   double max_translation_m = 0.05, double max_difference = 0.01);

// A table like evo_ape/evo_rpe print.
std::string formatStatisticsTable(const std::string& title, const ErrorStatistics& stats,
                                  const std::string& unit);

}  // namespace nidevo

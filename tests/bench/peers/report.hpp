#pragma once
// What one method did on one sequence, and the tables, CSV and JSON made of many of them.
#include <string>
#include <vector>

namespace nidevo::bench {

struct MethodRun {
  std::string sequence;
  std::string method;
  size_t frames = 0;
  double ate_rmse_m = 0;
  double rpe_translation_rmse_m = 0;  // frame to frame
  double rpe_rotation_rmse_deg = 0;
  int failures = 0;         // frames the method itself reported as failed (not OK)
  int silent_failures = 0;  // reported good, but over 2 deg or 5 cm off since the previous frame
  double median_ms = 0;     // time per frame, one thread
  double p95_ms = 0;
};

std::string formatTable(const std::vector<MethodRun>& runs);
// Per method: median and max ATE over the sequences, wins (lowest ATE of a sequence), silent
// failures in all, median time per frame and its ratio to NIDEVO's on the same sequences.
std::string formatSummary(const std::vector<MethodRun>& runs);
std::string formatCsv(const std::vector<MethodRun>& runs);
std::string formatJson(const std::vector<MethodRun>& runs);

}  // namespace nidevo::bench

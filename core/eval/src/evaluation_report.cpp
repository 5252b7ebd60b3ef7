#include "nidevo/eval/evaluation_report.hpp"

#include <cstdio>
#include <iostream>

#include "nidevo/eval/metrics.hpp"
#include "nidevo/eval/trajectory_plot.hpp"

namespace nidevo::cli {

void printEvaluation(const Trajectory& estimate, const Trajectory& reference,
                     double max_time_difference, int rpe_delta, const std::string& plot_path,
                     const std::string& title, double estimate_offset_s) {
  const auto matched =
      matchByTimestamp(estimate, reference, max_time_difference, estimate_offset_s);
  const auto ate = computeAte(matched);
  const auto rpe = computeRpe(matched, rpe_delta);
  const std::string delta = std::to_string(rpe_delta) + (rpe_delta == 1 ? " frame" : " frames");
  std::printf("matched %zu of %zu estimated poses\n\n", matched.estimate.size(), estimate.size());
  std::cout << formatStatisticsTable("APE w.r.t. translation part", ate.translation, "m") << "\n"
            << formatStatisticsTable("RPE translation, delta " + delta, rpe.translation, "m")
            << "\n"
            << formatStatisticsTable("RPE rotation, delta " + delta, rpe.rotation, "deg");
  if (!plot_path.empty()) {
    char text[64];
    std::snprintf(text, sizeof(text), "ATE RMSE %.4f m over %zu poses", ate.translation.rmse,
                  ate.translation.count);
    writeTrajectoryPlot(plot_path, ate.reference, ate.aligned_estimate, title + text);
    std::printf("\nplot written to %s\n", plot_path.c_str());
  }
}

}  // namespace nidevo::cli

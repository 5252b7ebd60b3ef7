// nidevo-eval: ATE and RPE of a TUM trajectory against ground truth, as evo reports them.
#include <cstdio>
#include <iostream>

#include "absl/flags/flag.h"
#include "cli.hpp"
#include "nidevo/metrics.hpp"
#include "nidevo/trajectory_plot.hpp"

ABSL_FLAG(std::string, plot, "", "Write a PNG plot (top and side views) to this path");
ABSL_FLAG(int, rpe_delta, 1, "RPE frame delta");
ABSL_FLAG(double, max_time_difference, 0.01,
          "Maximum timestamp difference when matching poses (s)");

int main(int argc, char** argv) {
  auto args = nidevo::cli::init(
      argc, argv,
      "Evaluates a TUM trajectory against ground truth: ATE after a rigid alignment without scale "
      "(Umeyama), and RPE.\nUsage: nidevo-eval GROUNDTRUTH.txt ESTIMATE.txt [--plot out.png]");
  if (args.size() != 2) {
    return nidevo::cli::usageError("expected two arguments: GROUNDTRUTH.txt ESTIMATE.txt");
  }
  try {
    const auto reference = nidevo::readTumTrajectory(args[0]);
    const auto estimate = nidevo::readTumTrajectory(args[1]);
    const auto matched =
        nidevo::matchByTimestamp(estimate, reference, absl::GetFlag(FLAGS_max_time_difference));
    const auto ate = nidevo::computeAte(matched);
    const auto rpe = nidevo::computeRpe(matched, absl::GetFlag(FLAGS_rpe_delta));
    std::printf("matched %zu of %zu estimated poses\n\n", matched.estimate.size(), estimate.size());
    std::cout << nidevo::formatStatisticsTable("APE w.r.t. translation part", ate.translation, "m")
              << "\n"
              << nidevo::formatStatisticsTable("RPE translation, delta " +
                                                   std::to_string(absl::GetFlag(FLAGS_rpe_delta)) +
                                                   " frames",
                                               rpe.translation, "m")
              << "\n"
              << nidevo::formatStatisticsTable("RPE rotation", rpe.rotation, "deg");
    const std::string plot = absl::GetFlag(FLAGS_plot);
    if (!plot.empty()) {
      char title[128];
      std::snprintf(title, sizeof(title), "ATE RMSE %.4f m over %zu poses", ate.translation.rmse,
                    ate.translation.count);
      nidevo::writeTrajectoryPlot(plot, ate.reference, ate.aligned_estimate, title);
      std::printf("\nplot written to %s\n", plot.c_str());
    }
  } catch (const std::exception& e) {
    std::cerr << "nidevo-eval: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

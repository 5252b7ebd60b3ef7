// nidevo-eval: ATE and RPE of a TUM trajectory against ground truth, as evo reports them.
#include <cstdio>
#include <iostream>

#include "absl/flags/flag.h"
#include "nidevo/cli/cli.hpp"
#include "nidevo/eval/evaluation_report.hpp"
#include "nidevo/io/trajectory.hpp"

ABSL_FLAG(std::string, plot, "", "Write a PNG plot (top and side views) to this path");
ABSL_FLAG(int, rpe_delta, 1, "RPE frame delta");
ABSL_FLAG(double, max_time_difference, 0.01,
          "Maximum timestamp difference when matching poses (s)");
ABSL_FLAG(double, offset, 0.0,
          "Added to the estimate's timestamps before matching (s), as TUM's evaluate_ate.py "
          "--offset: a sensor stamping its frames L seconds after capture matches best at -L");

int main(int argc, char** argv) {
  auto args = nidevo::cli::init(
      argc, argv,
      "Evaluates a TUM trajectory against ground truth: ATE after a rigid alignment without scale "
      "(Umeyama), and RPE.\nUsage: nidevo-eval GROUNDTRUTH.txt ESTIMATE.txt [--plot out.png] "
      "[--offset SECONDS]");
  if (args.size() != 2) {
    return nidevo::cli::usageError("expected two arguments: GROUNDTRUTH.txt ESTIMATE.txt");
  }
  try {
    const auto reference = nidevo::readTumTrajectory(args[0]);
    const auto estimate = nidevo::readTumTrajectory(args[1]);
    nidevo::cli::printEvaluation(estimate, reference, absl::GetFlag(FLAGS_max_time_difference),
                                 absl::GetFlag(FLAGS_rpe_delta), absl::GetFlag(FLAGS_plot), "",
                                 absl::GetFlag(FLAGS_offset));
  } catch (const std::exception& e) {
    std::cerr << "nidevo-eval: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

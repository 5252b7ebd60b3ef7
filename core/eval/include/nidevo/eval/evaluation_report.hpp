#pragma once
// The evaluation the offline tools print: ATE and RPE tables as evo reports them, and the plot.
#include <string>

#include "nidevo/io/trajectory.hpp"

namespace nidevo::cli {

// Matches by timestamp, prints the APE and RPE tables to stdout and, if plot_path is not empty,
// writes the plot titled "<title>ATE RMSE ...". Throws on too few matches or a failed write.
// estimate_offset_s shifts the estimate's timestamps before matching (matchByTimestamp).
void printEvaluation(const Trajectory& estimate, const Trajectory& reference,
                     double max_time_difference, int rpe_delta, const std::string& plot_path,
                     const std::string& title, double estimate_offset_s = 0.0);

}  // namespace nidevo::cli

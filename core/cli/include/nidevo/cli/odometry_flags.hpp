#pragma once
// Command-line flags for every OdometryConfig field the tools expose.
#include "nidevo/odometry/odometry_config.hpp"

namespace nidevo::cli {

// Reads the --cell_size, --normal_stride, ... flags over the defaults. Throws
// std::invalid_argument naming the bad flag.
OdometryConfig odometryConfigFromFlags();

}  // namespace nidevo::cli

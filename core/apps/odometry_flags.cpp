#include "odometry_flags.hpp"

#include <stdexcept>

#include "absl/flags/flag.h"

namespace {
const nidevo::OdometryConfig kDefaults;
}

ABSL_FLAG(int, cell_size, kDefaults.cell_size, "Normal-map box filter side (paper Table 3)");
ABSL_FLAG(int, normal_stride, kDefaults.normal_stride,
          "Normal map at 1/stride of the input resolution (1 = full, 2 = half)");
ABSL_FLAG(std::string, rotation_method, nidevo::toString(kDefaults.rotation_method),
          "best_pair (paper) or closed_form (SVD over all planes)");
ABSL_FLAG(double, min_plane_fraction, kDefaults.min_plane_fraction,
          "Smallest plane, as a fraction of the normal map's pixels");
ABSL_FLAG(int, projection_width, kDefaults.projection_width, "Orthographic projection width");
ABSL_FLAG(int, projection_height, kDefaults.projection_height, "Orthographic projection height");
ABSL_FLAG(int, projection_stride, kDefaults.projection_stride,
          "Project every n-th input pixel in u and v");
ABSL_FLAG(bool, kcc_depth, kDefaults.kcc_use_depth, "Correlate depth as a second KCC channel");
ABSL_FLAG(bool, subpixel, kDefaults.subpixel_peak, "Sub-pixel refinement of the KCC peak");
ABSL_FLAG(double, psr_bound, kDefaults.psr_bound, "Translation keyframe renewed at or below this PSR");

namespace nidevo::cli {

OdometryConfig odometryConfigFromFlags() {
  OdometryConfig c;
  c.cell_size = absl::GetFlag(FLAGS_cell_size);
  c.normal_stride = absl::GetFlag(FLAGS_normal_stride);
  c.rotation_method = parseRotationMethod(absl::GetFlag(FLAGS_rotation_method));
  c.min_plane_fraction = float(absl::GetFlag(FLAGS_min_plane_fraction));
  c.projection_width = absl::GetFlag(FLAGS_projection_width);
  c.projection_height = absl::GetFlag(FLAGS_projection_height);
  c.projection_stride = absl::GetFlag(FLAGS_projection_stride);
  c.kcc_use_depth = absl::GetFlag(FLAGS_kcc_depth);
  c.subpixel_peak = absl::GetFlag(FLAGS_subpixel);
  c.psr_bound = float(absl::GetFlag(FLAGS_psr_bound));
  if (auto e = c.validate(); !e.empty()) throw std::invalid_argument(e);
  return c;
}

}  // namespace nidevo::cli

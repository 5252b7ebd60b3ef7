#pragma once
// Stage 3a: orthographic projection of a rotated point cloud (paper Eq. 3) into grey and depth
// images: u = x / r + W/2, v = y / r + H/2, nearest point wins.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "nidevo/odometry/selection.hpp"

namespace nidevo {

// Input cloud: points with z > 0 are valid; intensity in [0, 1] per point.
struct CloudView {
  const float* x = nullptr;  // coordinates, one array each
  const float* y = nullptr;
  const float* z = nullptr;
  const float* intensity = nullptr;
  size_t size = 0;
  const float* weight = nullptr;  // per point contrast weight in [0, 1]; nullptr: all 1
};

struct OrthoImage {
  int width = 0;
  int height = 0;
  std::vector<float> gray;    // 0.5 where empty (authors)
  std::vector<float> depth;   // metres along the projection axis, 0 where empty
  std::vector<float> weight;  // contrast weight of the point in the cell
  void resize(int w, int h);
  int filledCount() const;
};

class OrthoProjector {
 public:
  // Resolution r (m/px) such that a fraction `inlier_fraction` of the rotated points falls inside
  // a width x height image. Returns 0 when the cloud has no valid point.
  double resolutionFor(const CloudView& cloud, const Eigen::Matrix3f& R, int width, int height,
                       double inlier_fraction);
  // Projects R * p for every valid p. Reuses `out`'s buffers.
  void project(const CloudView& cloud, const Eigen::Matrix3f& R, double resolution, int width,
               int height, OrthoImage* out);
  // Fills runs of at most max_gap empty cells, first along rows then along columns, by linear
  // interpolation when the cells on both sides lie on one surface (depths within
  // relative_depth_jump). A slanted surface spreads its points apart in the projection; left
  // alone, those holes form a moire that the correlator would lock onto.
  void fillGaps(OrthoImage* image, int max_gap, float relative_depth_jump);
  // Sets empty cells to the mean grey of the filled ones and scales each cell's contrast about
  // that mean by its weight, so that the outline of the field of view, which moves with the
  // camera's rotation and not with the scene, carries no contrast.
  static void flattenOutline(OrthoImage* image);

 private:
  std::vector<float> scratch_;
  KthSmallest kth_smallest_;
  std::vector<int> cell_;          // project: each point's cell, -1 if none
  std::vector<float> cell_depth_;  // project: each point's depth along the projection axis
  std::vector<int> column_last_;   // fillGaps: last filled row of each column
  std::vector<int> column_from_;   // fillGaps: per column, the row before a gap ending here, or -1
  std::vector<uint64_t> row_filled_;  // fillGaps: one bit per cell of a row, set where filled
};

}  // namespace nidevo

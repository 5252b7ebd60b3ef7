#include "nidevo/ortho_projection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace nidevo {

void OrthoImage::resize(int w, int h) {
  width = w;
  height = h;
  gray.resize(size_t(w) * size_t(h));
  depth.resize(size_t(w) * size_t(h));
  weight.resize(size_t(w) * size_t(h));
}

int OrthoImage::filledCount() const {
  int n = 0;
  for (float d : depth) n += d > 0.f;
  return n;
}

double OrthoProjector::resolutionFor(const CloudView& cloud, const Eigen::Matrix3f& R, int width,
                                     int height, double inlier_fraction) {
  scratch_.resize(cloud.size);
  size_t k = 0;
  const float sx = 2.f / float(width), sy = 2.f / float(height);
  for (size_t i = 0; i < cloud.size; ++i) {
    if (cloud.points[i].z() <= 0.f) continue;
    const Eigen::Vector3f p = R * cloud.points[i];
    scratch_[k++] = std::max(std::abs(p.x()) * sx, std::abs(p.y()) * sy);
  }
  if (k == 0) return 0.0;
  const size_t q = std::min(k - 1, size_t(std::ceil(inlier_fraction * double(k))) - 1);
  std::nth_element(scratch_.begin(), scratch_.begin() + long(q), scratch_.begin() + long(k));
  return std::max(double(scratch_[q]), 1e-6);
}

void OrthoProjector::project(const CloudView& cloud, const Eigen::Matrix3f& R, double resolution,
                             int width, int height, OrthoImage* out) {
  out->resize(width, height);
  std::fill(out->gray.begin(), out->gray.end(), 0.5f);
  std::fill(out->depth.begin(), out->depth.end(), std::numeric_limits<float>::infinity());
  const float inv_r = float(1.0 / resolution);
  const float half_w = float(width) / 2, half_h = float(height) / 2;
  for (size_t i = 0; i < cloud.size; ++i) {
    if (cloud.points[i].z() <= 0.f) continue;
    const Eigen::Vector3f p = R * cloud.points[i];
    const int u = int(std::floor(p.x() * inv_r + half_w));
    const int v = int(std::floor(p.y() * inv_r + half_h));
    if (u < 0 || v < 0 || u >= width || v >= height || p.z() <= 0.f) continue;
    const size_t c = size_t(v) * size_t(width) + size_t(u);
    if (p.z() < out->depth[c]) {
      out->depth[c] = p.z();
      out->gray[c] = cloud.intensity[i];
      out->weight[c] = cloud.weight ? cloud.weight[i] : 1.f;
    }
  }
  for (float& d : out->depth)
    if (std::isinf(d)) d = 0.f;
}

namespace {

// One row of cells.
void fillRow(float* gray, float* depth, float* weight, int count, int max_gap, float jump) {
  constexpr size_t stride = 1;
  int last = -1;  // last filled cell
  for (int i = 0; i < count; ++i) {
    if (depth[size_t(i) * stride] <= 0.f) continue;
    const int gap = i - last - 1;
    if (last >= 0 && gap > 0 && gap <= max_gap) {
      const float z0 = depth[size_t(last) * stride], z1 = depth[size_t(i) * stride];
      if (std::abs(z1 - z0) <= jump * std::min(z0, z1)) {
        const float g0 = gray[size_t(last) * stride], g1 = gray[size_t(i) * stride];
        const float w0 = weight[size_t(last) * stride], w1 = weight[size_t(i) * stride];
        for (int k = last + 1; k < i; ++k) {
          const float t = float(k - last) / float(i - last);
          depth[size_t(k) * stride] = z0 + t * (z1 - z0);
          gray[size_t(k) * stride] = g0 + t * (g1 - g0);
          weight[size_t(k) * stride] = w0 + t * (w1 - w0);
        }
      }
    }
    last = i;
  }
}

}  // namespace

void OrthoProjector::fillGaps(OrthoImage* img, int max_gap, float relative_depth_jump) {
  if (max_gap <= 0) return;
  const int W = img->width, H = img->height;
  for (int v = 0; v < H; ++v) {
    fillRow(&img->gray[size_t(v) * W], &img->depth[size_t(v) * W], &img->weight[size_t(v) * W], W,
            max_gap, relative_depth_jump);
  }
  // Columns the same way, but walked row by row with one state per column: a column walk
  // would touch a new cache line at every cell.
  column_last_.assign(size_t(W), -1);
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const size_t c = size_t(v) * W + u;
      if (img->depth[c] <= 0.f) continue;
      int& last = column_last_[size_t(u)];
      const int gap = v - last - 1;
      if (last >= 0 && gap > 0 && gap <= max_gap) {
        const size_t c0 = size_t(last) * W + u;
        const float z0 = img->depth[c0], z1 = img->depth[c];
        if (std::abs(z1 - z0) <= relative_depth_jump * std::min(z0, z1)) {
          const float g0 = img->gray[c0], g1 = img->gray[c];
          const float w0 = img->weight[c0], w1 = img->weight[c];
          for (int k = last + 1; k < v; ++k) {
            const float t = float(k - last) / float(v - last);
            const size_t ck = size_t(k) * W + u;
            img->depth[ck] = z0 + t * (z1 - z0);
            img->gray[ck] = g0 + t * (g1 - g0);
            img->weight[ck] = w0 + t * (w1 - w0);
          }
        }
      }
      last = v;
    }
  }
}

void OrthoProjector::flattenOutline(OrthoImage* img) {
  double sum = 0, weights = 0;
  for (size_t i = 0; i < img->depth.size(); ++i) {
    if (img->depth[i] > 0.f) {
      sum += double(img->weight[i]) * img->gray[i];
      weights += img->weight[i];
    }
  }
  if (weights <= 0) return;
  const float mean = float(sum / weights);
  for (size_t i = 0; i < img->depth.size(); ++i) {
    img->gray[i] = img->depth[i] > 0.f ? mean + img->weight[i] * (img->gray[i] - mean) : mean;
  }
}

}  // namespace nidevo

#include "nidevo/odometry/ortho_projection.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "vector_clones.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

namespace {

// R p row by row, in Eigen's order of operations (r0 x + (r1 y + r2 z)), which keeps the results
// those of Matrix3f * Vector3f.
struct Rotation {
  float r00, r01, r02, r10, r11, r12, r20, r21, r22;
  explicit Rotation(const Eigen::Matrix3f& R)
      : r00(R(0, 0)),
        r01(R(0, 1)),
        r02(R(0, 2)),
        r10(R(1, 0)),
        r11(R(1, 1)),
        r12(R(1, 2)),
        r20(R(2, 0)),
        r21(R(2, 1)),
        r22(R(2, 2)) {}
  float x(float px, float py, float pz) const { return r00 * px + (r01 * py + r02 * pz); }
  float y(float px, float py, float pz) const { return r10 * px + (r11 * py + r12 * pz); }
  float z(float px, float py, float pz) const { return r20 * px + (r21 * py + r22 * pz); }
};

// The loops below run on restrict pointers and select with masks (no branches), so that they
// vectorise.

// Per point, the half-extent max(|x| 2/W, |y| 2/H) of R p in units of the image's half-size,
// or infinity for a point without depth (those sort after every valid one).
NIDEVO_VECTOR_CLONES void halfExtents(const float* __restrict x, const float* __restrict y,
                                      const float* __restrict z, size_t n, const Rotation& R,
                                      float sx, float sy, float* __restrict extent) {
  for (size_t i = 0; i < n; ++i) {
    const float px = R.x(x[i], y[i], z[i]), py = R.y(x[i], y[i], z[i]);
    const float e = std::max(std::abs(px) * sx, std::abs(py) * sy);
    extent[i] = z[i] > 0.f ? e : std::numeric_limits<float>::infinity();
  }
}

// Per point, the cell of R p (-1 if p or R p is not in front, or R p falls outside the image) and
// the depth of R p. fu in [0, width) is floor(fu) in [0, width - 1], and int() truncates like
// floor there.
NIDEVO_VECTOR_CLONES void projectionCells(const float* __restrict x, const float* __restrict y,
                                          const float* __restrict z, size_t n, const Rotation& R,
                                          float inv_r, int width, int height, int* __restrict cell,
                                          float* __restrict depth) {
  const float half_w = float(width) / 2, half_h = float(height) / 2;
  const float fw = float(width), fh = float(height);
  for (size_t i = 0; i < n; ++i) {
    const float px = R.x(x[i], y[i], z[i]), py = R.y(x[i], y[i], z[i]), pz = R.z(x[i], y[i], z[i]);
    const float fu = px * inv_r + half_w, fv = py * inv_r + half_h;
    const bool inside =
        (z[i] > 0.f) & (pz > 0.f) & (fu >= 0.f) & (fu < fw) & (fv >= 0.f) & (fv < fh);
    const int u = int(inside ? fu : 0.f), v = int(inside ? fv : 0.f);
    cell[i] = inside ? v * width + u : -1;
    depth[i] = pz;
  }
}

// a where mask is all ones, b where it is zero: a select the compiler cannot turn back into a
// branch.
float select(uint32_t mask, float a, float b) {
  uint32_t ia, ib;
  std::memcpy(&ia, &a, sizeof ia);
  std::memcpy(&ib, &b, sizeof ib);
  const uint32_t r = (ia & mask) | (ib & ~mask);
  float out;
  std::memcpy(&out, &r, sizeof out);
  return out;
}

// The z-buffer: each cell keeps the nearest of the points that fall in it. Selects instead of a
// branch on "nearer": which point wins changes from point to point without a pattern the CPU
// can predict, and the mispredictions cost more than three unconditional stores.
void keepNearest(const int* __restrict cell, const float* __restrict cell_depth,
                 const float* __restrict intensity, const float* __restrict point_weight, size_t n,
                 float* __restrict depth, float* __restrict gray, float* __restrict weight) {
  for (size_t i = 0; i < n; ++i) {
    const int c = cell[i];
    if (c < 0) continue;
    const float z = cell_depth[i], d = depth[c];
    const uint32_t nearer = 0u - uint32_t((d == 0.f) | (z < d));
    depth[c] = select(nearer, z, d);
    gray[c] = select(nearer, intensity[i], gray[c]);
    weight[c] = select(nearer, point_weight ? point_weight[i] : 1.f, weight[c]);
  }
}

}  // namespace

double OrthoProjector::resolutionFor(const CloudView& cloud, const Eigen::Matrix3f& R, int width,
                                     int height, double inlier_fraction) {
  scratch_.resize(cloud.size);
  kth_smallest_.reserve(cloud.size);
  halfExtents(cloud.x, cloud.y, cloud.z, cloud.size, Rotation(R), 2.f / float(width),
              2.f / float(height), scratch_.data());
  size_t k = 0;
  for (size_t i = 0; i < cloud.size; ++i) k += cloud.z[i] > 0.f;
  if (k == 0) return 0.0;
  // The quantile among the k valid points: the invalid ones rank after them all.
  const size_t q = std::min(k - 1, size_t(std::ceil(inlier_fraction * double(k))) - 1);
  return std::max(double(kth_smallest_(scratch_.data(), cloud.size, q)), 1e-6);
}

void OrthoProjector::project(const CloudView& cloud, const Eigen::Matrix3f& R, double resolution,
                             int width, int height, OrthoImage* out) {
  out->resize(width, height);
  std::fill(out->gray.begin(), out->gray.end(), 0.5f);
  std::fill(out->depth.begin(), out->depth.end(), 0.f);  // 0: empty
  // First every point's cell, vectorised; then the z-buffer, a scatter that stays scalar.
  cell_.resize(cloud.size);
  cell_depth_.resize(cloud.size);
  projectionCells(cloud.x, cloud.y, cloud.z, cloud.size, Rotation(R), float(1.0 / resolution),
                  width, height, cell_.data(), cell_depth_.data());
  keepNearest(cell_.data(), cell_depth_.data(), cloud.intensity, cloud.weight, cloud.size,
              out->depth.data(), out->gray.data(), out->weight.data());
}

namespace {

// Cells last+1 .. next-1 of a line (cell i at i * stride) take values interpolated between cells
// last and next, when those lie on one surface.
void interpolateGap(float* gray, float* depth, float* weight, size_t stride, int last, int next,
                    float jump) {
  const size_t c0 = size_t(last) * stride, c1 = size_t(next) * stride;
  const float z0 = depth[c0], z1 = depth[c1];
  if (!(std::abs(z1 - z0) <= jump * std::min(z0, z1))) return;
  const float g0 = gray[c0], g1 = gray[c1], w0 = weight[c0], w1 = weight[c1];
  for (int k = last + 1; k < next; ++k) {
    const float t = float(k - last) / float(next - last);
    const size_t ck = size_t(k) * stride;
    depth[ck] = z0 + t * (z1 - z0);
    gray[ck] = g0 + t * (g1 - g0);
    weight[ck] = w0 + t * (w1 - w0);
  }
}

// Bit i % 64 of words[i / 64]: cell i of the row is filled. SSE2 compares four cells at once.
void filledMask(const float* depth, int count, uint64_t* words) {
  for (int w = 0; w * 64 < count; ++w) {
    const int begin = w * 64, end = std::min(count, begin + 64);
    uint64_t bits = 0;
    int i = begin;
#if defined(__SSE2__)
    const __m128 zero = _mm_setzero_ps();
    for (; i + 4 <= end; i += 4) {
      const int four = _mm_movemask_ps(_mm_cmpgt_ps(_mm_loadu_ps(depth + i), zero));
      bits |= uint64_t(unsigned(four)) << (i - begin);
    }
#endif
    for (; i < end; ++i) bits |= uint64_t(depth[i] > 0.f) << (i - begin);
    words[w] = bits;
  }
}

// The first filled cell at or after `from`, or -1.
int nextFilled(const uint64_t* words, int word_count, int from) {
  int w = from / 64;
  if (w >= word_count) return -1;
  uint64_t bits = words[w] & (~uint64_t(0) << (from % 64));
  while (bits == 0) {
    if (++w == word_count) return -1;
    bits = words[w];
  }
  return w * 64 + __builtin_ctzll(bits);
}

// One row, gap by gap: the gaps' first cells (empty, filled on the left) come from the filled
// mask a word at a time, so that the cost follows the number of gaps, not of cells, and no
// branch depends on each cell (the cell-by-cell walk mispredicted at every run's end).
void fillRow(float* gray, float* depth, float* weight, int count, int max_gap, float jump,
             uint64_t* words) {
  filledMask(depth, count, words);
  const int word_count = (count + 63) / 64;
  for (int w = 0; w < word_count; ++w) {
    const uint64_t filled_left = (words[w] << 1) | (w > 0 ? words[w - 1] >> 63 : 0);
    uint64_t starts = ~words[w] & filled_left;
    if (count - w * 64 < 64) starts &= (uint64_t(1) << (count - w * 64)) - 1;
    while (starts != 0) {
      const int start = w * 64 + __builtin_ctzll(starts);
      starts &= starts - 1;
      const int next = nextFilled(words, word_count, start + 1);
      if (next < 0) return;  // no filled cell after the gap
      if (next - start <= max_gap) interpolateGap(gray, depth, weight, 1, start - 1, next, jump);
    }
  }
}

// One step of the column pass at row v: for every column, the last filled row before v
// (`last`, updated) and, where a fillable gap ends at row v, its first row - 1 in `from` (else
// -1). Branch-free so that it vectorises; returns whether any gap ends here.
NIDEVO_VECTOR_CLONES bool columnGapsEndingAt(const float* __restrict depth_row, int width, int v,
                                             int max_gap, int* __restrict last,
                                             int* __restrict from) {
  int any = 0;
  for (int u = 0; u < width; ++u) {
    const int l = last[u];
    const int filled = depth_row[u] > 0.f;
    const int gap = v - l - 1;
    const int ends = filled & (l >= 0) & (gap > 0) & (gap <= max_gap);
    from[u] = ends ? l : -1;
    any |= ends;
    last[u] = filled ? v : l;
  }
  return any != 0;
}

// visit(u) for every column u with from[u] >= 0, in order; four columns at a time, since a row
// where some gap ends has few of them among its hundreds of columns.
template <class Visit>
void forEachGapEnd(const int* from, int width, Visit&& visit) {
  int u = 0;
#if defined(__SSE2__)
  const __m128i none = _mm_set1_epi32(-1);
  for (; u + 4 <= width; u += 4) {
    const __m128i four = _mm_loadu_si128(reinterpret_cast<const __m128i*>(from + u));
    int bits = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(four, none)));
    while (bits != 0) {
      visit(u + __builtin_ctz(unsigned(bits)));
      bits &= bits - 1;
    }
  }
#endif
  for (; u < width; ++u)
    if (from[u] >= 0) visit(u);
}

}  // namespace

void OrthoProjector::fillGaps(OrthoImage* img, int max_gap, float relative_depth_jump) {
  if (max_gap <= 0) return;
  const int W = img->width, H = img->height;
  row_filled_.resize(size_t(W + 63) / 64);
  for (int v = 0; v < H; ++v) {
    fillRow(&img->gray[size_t(v) * W], &img->depth[size_t(v) * W], &img->weight[size_t(v) * W], W,
            max_gap, relative_depth_jump, row_filled_.data());
  }
  // Columns the same way, but walked row by row with one state per column: a column walk
  // would touch a new cache line at every cell.
  column_last_.assign(size_t(W), -1);
  column_from_.resize(size_t(W));
  for (int v = 0; v < H; ++v) {
    if (!columnGapsEndingAt(&img->depth[size_t(v) * W], W, v, max_gap, column_last_.data(),
                            column_from_.data())) {
      continue;
    }
    forEachGapEnd(column_from_.data(), W, [&](int u) {
      interpolateGap(&img->gray[size_t(u)], &img->depth[size_t(u)], &img->weight[size_t(u)],
                     size_t(W), column_from_[size_t(u)], v, relative_depth_jump);
    });
  }
}

namespace {

// Filled cells' grey values towards `mean` by their weight; empty cells take it.
NIDEVO_VECTOR_CLONES void fadeTowardsMean(const float* __restrict depth,
                                          const float* __restrict weight, size_t n, float mean,
                                          float* __restrict gray) {
  for (size_t i = 0; i < n; ++i)
    gray[i] = depth[i] > 0.f ? mean + weight[i] * (gray[i] - mean) : mean;
}

}  // namespace

void OrthoProjector::flattenOutline(OrthoImage* img) {
  double sum = 0, weights = 0;
  const float* __restrict depth = img->depth.data();
  const float* __restrict weight = img->weight.data();
  const float* __restrict gray = img->gray.data();
  // Without a branch: filled and empty cells alternate too irregularly to predict. An empty
  // cell adds zeros, which leaves the sums' bits as they were.
  for (size_t i = 0; i < img->depth.size(); ++i) {
    const double w = depth[i] > 0.f ? double(weight[i]) : 0.0;
    sum += w * gray[i];
    weights += w;
  }
  if (weights <= 0) return;
  fadeTowardsMean(img->depth.data(), img->weight.data(), img->depth.size(), float(sum / weights),
                  img->gray.data());
}

}  // namespace nidevo

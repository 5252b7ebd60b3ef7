#include "nidevo/odometry/kcc.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "exp_in_place.hpp"
#include "vector_clones.hpp"

namespace nidevo {

namespace {

// FFTW's planner and plan destruction are not thread-safe; executing plans is.
std::mutex& plannerMutex() {
  static std::mutex m;
  return m;
}

std::complex<float>* allocComplex(size_t n) {
  return reinterpret_cast<std::complex<float>*>(fftwf_alloc_complex(n));
}

double energy(const float* x, size_t n) {
  double s = 0;
  for (size_t i = 0; i < n; ++i) s += double(x[i]) * x[i];
  return s;
}

// Complex products written out as std::complex's operator* computes them without its check for
// NaN results (which calls a library function and keeps the loop from vectorising): the same
// bits for finite inputs.
// out[i] += conj(a[i]) * b[i].
NIDEVO_VECTOR_CLONES void addConjugateProducts(const std::complex<float>* a,
                                               const std::complex<float>* b, size_t n,
                                               std::complex<float>* out) {
  const float* x = reinterpret_cast<const float*>(a);
  const float* y = reinterpret_cast<const float*>(b);
  float* z = reinterpret_cast<float*>(out);
  for (size_t i = 0; i < 2 * n; i += 2) {
    const float ar = x[i], ai = -x[i + 1], br = y[i], bi = y[i + 1];
    z[i] += ar * br - ai * bi;
    z[i + 1] += ar * bi + ai * br;
  }
}

// out[i] *= a[i].
NIDEVO_VECTOR_CLONES void multiply(const std::complex<float>* a, size_t n,
                                   std::complex<float>* out) {
  const float* x = reinterpret_cast<const float*>(a);
  float* z = reinterpret_cast<float*>(out);
  for (size_t i = 0; i < 2 * n; i += 2) {
    const float zr = z[i], zi = z[i + 1], ar = x[i], ai = x[i + 1];
    z[i] = zr * ar - zi * ai;
    z[i + 1] = zr * ai + zi * ar;
  }
}

// out[i] = -(squared distance of the shift) / (sigma^2 n), the Gaussian kernel's exponent,
// from the cross-correlation in out.
NIDEVO_VECTOR_CLONES void kernelExponents(float sum, float inv_n, float scale, size_t n,
                                          float* out) {
  for (size_t i = 0; i < n; ++i) out[i] = std::max(0.f, sum - 2.f * out[i] * inv_n) * scale;
}

// The first index of the largest value, as a scalar walk keeping the first of equal maxima
// finds it; four at a time (the maximum of floats is exact, so the walk's answer is the first
// index holding it). With a NaN anywhere the scalar walk decides, whose comparisons skip it.
size_t firstMaximum(const float* x, size_t n) {
  auto scalar = [&] {
    size_t best = 0;
    for (size_t i = 1; i < n; ++i)
      if (x[i] > x[best]) best = i;
    return best;
  };
#if defined(__SSE2__)
  if (n < 8) return scalar();
  __m128 top = _mm_loadu_ps(x), unordered = _mm_cmpunord_ps(top, top);
  size_t i = 4;
  for (; i + 4 <= n; i += 4) {
    const __m128 v = _mm_loadu_ps(x + i);
    unordered = _mm_or_ps(unordered, _mm_cmpunord_ps(v, v));
    top = _mm_max_ps(top, v);
  }
  float lanes[4];
  _mm_storeu_ps(lanes, top);
  float largest = std::max(std::max(lanes[0], lanes[1]), std::max(lanes[2], lanes[3]));
  bool nan = _mm_movemask_ps(unordered) != 0;
  for (; i < n; ++i) nan = nan || std::isnan(x[i]), largest = std::max(largest, x[i]);
  if (nan) return scalar();
  for (size_t k = 0; k < n; ++k)
    if (x[k] == largest) return k;
  return 0;
#else
  return scalar();
#endif
}

// visit(i) for every i with !(x[i] < floor), in order: the cells above a floor that only the
// tops of the strongest peaks reach, found four at a time.
template <class Visit>
void forEachNotBelow(const float* x, size_t n, float floor, Visit&& visit) {
  size_t i = 0;
#if defined(__SSE2__)
  const __m128 f = _mm_set1_ps(floor);
  for (; i + 4 <= n; i += 4) {
    int bits = _mm_movemask_ps(_mm_cmpnlt_ps(_mm_loadu_ps(x + i), f));
    while (bits != 0) {
      visit(i + size_t(__builtin_ctz(unsigned(bits))));
      bits &= bits - 1;
    }
  }
#endif
  for (; i < n; ++i)
    if (!(x[i] < floor)) visit(i);
}

}  // namespace

KernelCrossCorrelator::KernelCrossCorrelator(int width, int height, int channels, double sigma,
                                             double lambda, double label_sigma, bool measure_plans)
    : width_(width), height_(height), channels_(channels), sigma_(sigma), lambda_(lambda) {
  if (width < 4 || height < 4 || channels < 1) {
    throw std::invalid_argument("KernelCrossCorrelator: bad size or channel count");
  }
  n_real_ = size_t(width) * size_t(height);
  n_complex_ = size_t(height) * size_t(width / 2 + 1);
  real_ = fftwf_alloc_real(n_real_);
  response_ = fftwf_alloc_real(n_real_);
  spectrum_ = allocComplex(n_complex_);
  alpha_hat_ = allocComplex(n_complex_);
  for (int c = 0; c < channels; ++c) {
    key_hat_.push_back(allocComplex(n_complex_));
    cur_hat_.push_back(allocComplex(n_complex_));
  }
  std::lock_guard<std::mutex> lock(plannerMutex());
  // With FFTW_MEASURE, later plans of the same size reuse the process's wisdom.
  const unsigned flags = measure_plans ? FFTW_MEASURE : FFTW_ESTIMATE;
  // The forward transform reads a scratch copy (real_), which it may overwrite: that lets the
  // planner skip a copy of its own.
  plan_forward_ =
      fftwf_plan_dft_r2c_2d(height, width, real_, reinterpret_cast<fftwf_complex*>(spectrum_),
                            flags | FFTW_DESTROY_INPUT);
  plan_inverse_ = fftwf_plan_dft_c2r_2d(height, width, reinterpret_cast<fftwf_complex*>(spectrum_),
                                        real_, flags);
  if (!plan_forward_ || !plan_inverse_) throw std::runtime_error("FFTW planning failed");
  // The label y: a delta at the origin (sigma 0, the authors'), or a Gaussian of label_sigma px
  // centred on the origin with circular wrap, which makes the peak smooth enough to interpolate.
  label_hat_ = allocComplex(n_complex_);
  std::vector<float> label(n_real_, 0.f);
  if (label_sigma <= 0) {
    label[0] = 1.f;
  } else {
    for (int v = 0; v < height; ++v) {
      const int dv = std::min(v, height - v);
      for (int u = 0; u < width; ++u) {
        const int du = std::min(u, width - u);
        label[size_t(v) * size_t(width) + size_t(u)] =
            float(std::exp(-0.5 * (du * du + dv * dv) / (label_sigma * label_sigma)));
      }
    }
  }
  forward(label.data(), label_hat_);
}

KernelCrossCorrelator::~KernelCrossCorrelator() {
  {
    std::lock_guard<std::mutex> lock(plannerMutex());
    fftwf_destroy_plan(static_cast<fftwf_plan>(plan_forward_));
    fftwf_destroy_plan(static_cast<fftwf_plan>(plan_inverse_));
  }
  fftwf_free(real_);
  fftwf_free(response_);
  fftwf_free(spectrum_);
  fftwf_free(alpha_hat_);
  fftwf_free(label_hat_);
  for (auto* p : key_hat_) fftwf_free(p);
  for (auto* p : cur_hat_) fftwf_free(p);
}

void KernelCrossCorrelator::forward(const float* in, std::complex<float>* out) {
  std::copy(in, in + n_real_, real_);
  fftwf_execute_dft_r2c(static_cast<fftwf_plan>(plan_forward_), real_,
                        reinterpret_cast<fftwf_complex*>(out));
}

void KernelCrossCorrelator::forwardResponse(std::complex<float>* out) {
  // response_ and real_ both come from fftwf_alloc_real, so the plan's alignment holds.
  fftwf_execute_dft_r2c(static_cast<fftwf_plan>(plan_forward_), response_,
                        reinterpret_cast<fftwf_complex*>(out));
}

void KernelCrossCorrelator::gaussianCorrelation(const std::complex<float>* const* a, double aa,
                                                const std::complex<float>* const* b, double bb,
                                                float* out) {
  // Cross-correlation of every circular shift at once: IFFT(sum_c conj(A_c) * B_c).
  std::fill(spectrum_, spectrum_ + n_complex_, std::complex<float>(0.f, 0.f));
  for (int c = 0; c < channels_; ++c) addConjugateProducts(a[c], b[c], n_complex_, spectrum_);
  fftwf_execute_dft_c2r(static_cast<fftwf_plan>(plan_inverse_),
                        reinterpret_cast<fftwf_complex*>(spectrum_), out);
  const double n = double(n_real_);
  const float inv_n = float(1.0 / n);  // FFTW's inverse is unnormalised
  const float scale = float(-1.0 / (sigma_ * sigma_ * n));
  const float sum = float(aa + bb);
  kernelExponents(sum, inv_n, scale, n_real_, out);
  expInPlace(out, n_real_);
}

void KernelCrossCorrelator::train(const float* const* channels) {
  key_energy_ = 0;
  for (int c = 0; c < channels_; ++c) {
    key_energy_ += energy(channels[c], n_real_);
    forward(channels[c], key_hat_[size_t(c)]);
  }
  gaussianCorrelation(key_hat_.data(), key_energy_, key_hat_.data(), key_energy_, response_);
  forwardResponse(alpha_hat_);
  // Eq. 13: F(alpha) = F(y) / (F(k_xx) + lambda).
  const std::complex<float> lambda(float(lambda_), 0.f);
  for (size_t i = 0; i < n_complex_; ++i) alpha_hat_[i] = label_hat_[i] / (alpha_hat_[i] + lambda);
  trained_ = true;
}

KccMatch KernelCrossCorrelator::match(const float* const* channels, bool subpixel,
                                      int psr_exclusion, const KccShiftPrior* prior,
                                      int ridge_cells) {
  correlate(channels);
  const int W = width_;
  size_t best = firstMaximum(response_, n_real_);
  KccMatch m;
  if (prior) best = peakNearPrior(best, *prior, psr_exclusion, &m.rival_peaks);
  const int pu = int(best % size_t(W)), pv = int(best / size_t(W));
  m.peak = responseAt(pu, pv);
  m.du = signedShift(pu, W);
  m.dv = signedShift(pv, height_);
  if (subpixel) addSubpixelOffset(pu, pv, &m.du, &m.dv);
  m.psr = peakToSidelobe(pu, pv, m.peak, psr_exclusion);
  if (ridge_cells > 0 && m.peak > 0) {
    const int r = ridge_cells;
    m.ridge_u = std::max(responseAt(pu + r, pv), responseAt(pu - r, pv)) / m.peak;
    m.ridge_v = std::max(responseAt(pu, pv + r), responseAt(pu, pv - r)) / m.peak;
  }
  return m;
}

// Eqs. 14-15: the response of the trained filter to the current image, in response_.
void KernelCrossCorrelator::correlate(const float* const* channels) {
  double cur_energy = 0;
  for (int c = 0; c < channels_; ++c) {
    cur_energy += energy(channels[c], n_real_);
    forward(channels[c], cur_hat_[size_t(c)]);
  }
  gaussianCorrelation(key_hat_.data(), key_energy_, cur_hat_.data(), cur_energy, response_);
  forwardResponse(spectrum_);
  multiply(alpha_hat_, n_complex_, spectrum_);  // Eq. 15
  fftwf_execute_dft_c2r(static_cast<fftwf_plan>(plan_inverse_),
                        reinterpret_cast<fftwf_complex*>(spectrum_), response_);
}

bool KernelCrossCorrelator::isLocalMaximum(int u, int v) const {
  const double r = responseAt(u, v);
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x)
      if ((x || y) && responseAt(u + x, v + y) > r) return false;
  return true;
}

// Two passes over the response, one to choose and one to count rivals; only the cells above the
// ratio are looked at closely, and those are few (the tops of the strongest peaks).
size_t KernelCrossCorrelator::peakNearPrior(size_t best, const KccShiftPrior& prior, int exclusion,
                                            int* rivals) const {
  const int W = width_, H = height_;
  const float floor = float(prior.ratio) * response_[best];
  auto distance2 = [&](int u, int v, double du, double dv) {
    double dx = std::abs(signedShift(u, W) - du), dy = std::abs(signedShift(v, H) - dv);
    dx = std::min(dx, W - dx), dy = std::min(dy, H - dy);  // the response is circular
    return dx * dx + dy * dy;
  };
  auto forEachStrongMaximum = [&](auto&& visit) {
    forEachNotBelow(response_, n_real_, floor, [&](size_t i) {
      const int u = int(i % size_t(W)), v = int(i / size_t(W));
      if (isLocalMaximum(u, v)) visit(i, u, v);
    });
  };
  size_t chosen = best;
  double chosen_d2 = distance2(int(best % size_t(W)), int(best / size_t(W)), prior.du, prior.dv);
  forEachStrongMaximum([&](size_t i, int u, int v) {
    const double d2 = distance2(u, v, prior.du, prior.dv);
    if (d2 < chosen_d2) chosen = i, chosen_d2 = d2;
  });
  const double cu = signedShift(int(chosen % size_t(W)), W),
               cv = signedShift(int(chosen / size_t(W)), H);
  const double apart2 = double(exclusion) * double(exclusion);
  *rivals = 0;
  forEachStrongMaximum([&](size_t, int u, int v) { *rivals += distance2(u, v, cu, cv) > apart2; });
  return chosen;
}

double KernelCrossCorrelator::responseAt(int u, int v) const {
  const int W = width_, H = height_;
  return double(response_[size_t((v + H) % H) * size_t(W) + size_t((u + W) % W)]);
}

// Quadratic surface through the 3x3 neighbourhood of the peak, with the cross term, so that a
// diagonal ridge does not bias the axes; on logarithms where all are positive (exact for a
// Gaussian peak).
void KernelCrossCorrelator::addSubpixelOffset(int pu, int pv, double* du, double* dv) const {
  double f[3][3];
  bool positive = true;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x) {
      f[y + 1][x + 1] = responseAt(pu + x, pv + y);
      positive = positive && f[y + 1][x + 1] > 0;
    }
  if (positive)
    for (auto& row : f)
      for (double& value : row) value = std::log(value);
  const double gx = (f[1][2] - f[1][0]) / 2, gy = (f[2][1] - f[0][1]) / 2;
  const double hxx = f[1][2] - 2 * f[1][1] + f[1][0], hyy = f[2][1] - 2 * f[1][1] + f[0][1];
  const double hxy = (f[2][2] - f[2][0] - f[0][2] + f[0][0]) / 4;
  const double det = hxx * hyy - hxy * hxy;
  if (hxx < 0 && det > 0) {  // a maximum
    *du += std::clamp(-(hyy * gx - hxy * gy) / det, -0.5, 0.5);
    *dv += std::clamp(-(hxx * gy - hxy * gx) / det, -0.5, 0.5);
  }
}

// Eq. 17: (peak - mean) / std of the response outside the (2e+1)^2 window around the peak.
double KernelCrossCorrelator::peakToSidelobe(int pu, int pv, double peak, int exclusion) const {
  const int W = width_, H = height_;
  auto circular_distance = [](int a, int b, int n) {
    const int d = std::abs(a - b);
    return std::min(d, n - d);
  };
  // Rows that cross the window skip its columns; the others are summed whole. The cells are
  // visited in the same order either way, so the sums are those of one walk over the image.
  double sum = 0, sum2 = 0;
  size_t count = 0;
  for (int v = 0; v < H; ++v) {
    const float* row = response_ + size_t(v) * size_t(W);
    if (circular_distance(v, pv, H) > exclusion) {
      for (int u = 0; u < W; ++u) {
        const double r = row[u];
        sum += r;
        sum2 += r * r;
      }
      count += size_t(W);
      continue;
    }
    for (int u = 0; u < W; ++u) {
      if (circular_distance(u, pu, W) <= exclusion) continue;
      const double r = row[u];
      sum += r;
      sum2 += r * r;
      ++count;
    }
  }
  const double mean = sum / double(count);
  const double var = std::max(0.0, sum2 / double(count) - mean * mean);
  return var > 0 ? (peak - mean) / std::sqrt(var) : 0.0;
}

}  // namespace nidevo

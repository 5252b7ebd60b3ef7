#pragma once
// Stage 3b: kernel cross-correlator with a Gaussian kernel (paper Eqs. 11-15), on FFTW single
// precision. Plans and buffers are made once per instance; train/match do not allocate.
#include <complex>
#include <vector>

namespace nidevo {

struct KccMatch {
  // Shift of the current image against the trained one: cur(u, v) ~ key(u - du, v - dv).
  double du = 0;
  double dv = 0;
  double peak = 0;
  double psr = 0;  // Eq. 17, side lobe excludes (2*exclusion+1)^2 around the peak
  // Local maxima of at least KccShiftPrior::ratio of the highest one, more than the PSR
  // exclusion apart from the chosen peak: another shift that fits almost as well (a periodic
  // texture's next period). 0 without a prior.
  int rival_peaks = 0;
  // The response ridge_cells from the peak along u and along v (the higher side), as a fraction
  // of the peak: near 1 where the images leave the shift free along that axis (the projection
  // of a bare wall slides along it), low where the peak is sharp. 0 when not asked for.
  double ridge_u = 0;
  double ridge_v = 0;
};

// Where the motion model expects the peak. Among the local maxima of at least `ratio` times the
// highest response, the one nearest (du, dv) is chosen, so that a periodic texture's equal peaks
// cannot move the pose by a whole period; a clearly higher peak still wins wherever it is.
struct KccShiftPrior {
  double du = 0;
  double dv = 0;
  double ratio = 0.9;
};

class KernelCrossCorrelator {
 public:
  // label_sigma 0: delta label (the authors'); > 0: Gaussian label of that many pixels.
  // measure_plans: FFTW_MEASURE (timed, may pick a different algorithm in each process, so the
  // last bits of a result vary between runs) instead of FFTW_ESTIMATE (reproducible).
  KernelCrossCorrelator(int width, int height, int channels, double sigma, double lambda,
                        double label_sigma = 0.0, bool measure_plans = false);
  ~KernelCrossCorrelator();
  KernelCrossCorrelator(const KernelCrossCorrelator&) = delete;
  KernelCrossCorrelator& operator=(const KernelCrossCorrelator&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }

  // channels[c] points at width*height floats (row-major). Label: a delta at the origin.
  void train(const float* const* channels);
  bool trained() const { return trained_; }
  KccMatch match(const float* const* channels, bool subpixel, int psr_exclusion,
                 const KccShiftPrior* prior = nullptr, int ridge_cells = 0);
  // The last match's response (width*height, peak at the shift), for tests and debugging.
  const float* response() const { return response_; }

 private:
  void correlate(const float* const* channels);
  double responseAt(int u, int v) const;  // wraps around, the response is circular
  bool isLocalMaximum(int u, int v) const;
  size_t peakNearPrior(size_t best, const KccShiftPrior& prior, int exclusion, int* rivals) const;
  double signedShift(int p, int size) const { return p > size / 2 ? p - size : p; }
  void addSubpixelOffset(int pu, int pv, double* du, double* dv) const;
  double peakToSidelobe(int pu, int pv, double peak, int exclusion) const;
  void forward(const float* in, std::complex<float>* out);
  // The kernel in response_, transformed in place of a copy (the transform may overwrite it).
  void forwardResponse(std::complex<float>* out);
  void gaussianCorrelation(const std::complex<float>* const* a, double aa,
                           const std::complex<float>* const* b, double bb, float* out);

  int width_, height_, channels_;
  double sigma_, lambda_;
  size_t n_real_, n_complex_;
  void* plan_forward_ = nullptr;
  void* plan_inverse_ = nullptr;
  float* real_ = nullptr;
  float* response_ = nullptr;
  std::complex<float>* spectrum_ = nullptr;
  std::complex<float>* alpha_hat_ = nullptr;
  std::complex<float>* label_hat_ = nullptr;
  std::vector<std::complex<float>*> key_hat_;
  std::vector<std::complex<float>*> cur_hat_;
  double key_energy_ = 0;
  bool trained_ = false;
};

}  // namespace nidevo

#pragma once
// Verification (and a small refinement) of a full pose against a reference frame: a sparse
// sample of the reference's surface points, warped into the current frame with the pose
// hypothesis, must land on the current surface (point-to-plane residual, normal agreement) and
// on the same grey values. The refinement is Gauss-Newton on those point-to-plane residuals with
// projective association, updating only the directions the geometry constrains: along the others
// (a corridor's axis, a single plane's in-plane motion) the hypothesis is kept as it is.
#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "nidevo/odometry/camera.hpp"
#include "nidevo/odometry/normal_map.hpp"

namespace nidevo {

// Reference surface points, their normals and grey values, in the reference camera's frame.
struct SurfaceSample {
  std::vector<Eigen::Vector3f> point;
  std::vector<Eigen::Vector3f> normal;
  std::vector<float> intensity;
  size_t size() const { return point.size(); }
  void clear();
};

// Every `step`-th smooth pixel of the map, in u and v. intensity: one value per map pixel.
void sampleSurface(const NormalMap& map, const std::vector<float>& intensity, int step,
                   SurfaceSample* out);

// The current frame as the alignment reads it, built once per frame for all hypotheses and steps:
// one 16-byte load per warped point instead of four scattered ones, in an array half the size
// of the normal map's points and normals (which do not fit a core's L2 cache at 320x240).
struct AlignmentTarget {
  int width = 0;
  int height = 0;
  // Per map pixel: the surface's unit normal n and n . q for its point q; NaN where the map has
  // no valid normal.
  std::vector<Eigen::Vector4f> plane;
  // Per map pixel: grey value, a copy of the frame's so that the target stands alone (its
  // gradient is interpolated on demand: storing it measured no faster, for 0.9 MB more).
  std::vector<float> grey;
};

// map and intensity (one value per map pixel) of the current frame.
void buildAlignmentTarget(const NormalMap& map, const std::vector<float>& intensity,
                          AlignmentTarget* out);

// `fine` at half its width and height, for a coarse-to-fine alignment whose first steps reach
// farther: per 2x2 block the top-left pixel's plane (or the block's first valid one: the plane
// passes through that pixel's point, which lies within the block), and the grey values smoothed
// by [1 2 1] x [1 2 1] around the top-left pixel. map_camera.subsampled(2) is the camera of the
// coarse pixels.
void halveAlignmentTarget(const AlignmentTarget& fine, AlignmentTarget* out);

// A target halved once, twice..., with the camera of each level's pixels.
struct AlignmentPyramid {
  std::vector<AlignmentTarget> level;  // level[0]: half the finest target's size
  std::vector<Camera> camera;
  // Room for `levels` halvings of a target of fine_camera's pixels, so that building never
  // allocates.
  void reserve(int levels, const Camera& fine_camera);
  // Every level from `fine` (of the reserved size).
  void build(const AlignmentTarget& fine);
};

struct AlignmentParams {
  int iterations = 10;  // Gauss-Newton steps; 0: evaluate the hypothesis only
  // Converged when a step moves the surface less than this (rotation at the mean depth, and
  // translation), metres.
  float converged_m = 1e-4f;
  float max_distance_m = 0.08f;  // association gate on the point-to-plane residual
  float inlier_m = 0.02f;        // a residual below this (plus inlier_per_m * depth) is an inlier
  float inlier_per_m = 0.01f;    // depth noise grows with range
  float normal_dot = 0.8f;       // warped reference normal and current normal at least this aligned
  // A refinement that comes within this of an earlier hypothesis' refined pose (rotation as
  // metres at the mean depth, and translation) ends there with that result: both are in one
  // basin, and its remaining steps would only jitter about the same minimum. 0: never.
  float join_m = 0.0f;
  // alignCoarseToFine: the gate on a level halved k times is max_distance_m times this to the
  // power k (1: the same gate on every level).
  float coarse_gate_growth = 2.0f;
  // Grey-value residuals join the point-to-plane ones with this factor (metres per grey unit of
  // [0, 1]), so that texture fixes what the geometry leaves free; 0: geometry only.
  float photometric_weight = 0.1f;
  float photometric_huber = 0.05f;  // grey units
  // Steps with grey values after depth alone fixed all six directions (0: none).
  int polish_iterations = 3;
  // A direction too weak to update (eigenvalue below min_eigenvalue, at least this) whose
  // would-be step stays within confirm_step_m (metres at the mean depth) agrees with the
  // hypothesis: the data could have moved it and did not. 0: never confirmed.
  float confirm_eigenvalue = 0.0f;
  float confirm_step_m = 0.005f;
  // DepthAligner::untoldWeakDirections moves the pose this far (metres at the mean depth) either
  // way along each weak direction.
  float confirm_shift_m = 0.05f;
  float min_eigenvalue = 0.004f;  // normalised Hessian eigenvalue below which a direction is left
                                  // to the hypothesis
  // refineAlongWeakDirections steps along weak directions of at least this eigenvalue too; they
  // stay unconstrained, confirmed only when the steps moved the pose by at most confirm_step_m
  // along them. 0: off (align itself never moves a weak direction).
  float step_eigenvalue = 0.0f;
  // The inliers that pass may lose, as a fraction of the hypothesis' (a point or two at a
  // pixel's edge is noise, not the geometry objecting).
  float step_inlier_slack = 0.01f;
  // The grey-depth gap that matters (AlignmentResult::grey_depth_gap_rad): measured to its end
  // only where the first grey-value step reaches a quarter of it (a pass over the sample per
  // step; most frames' gap is far below). 0: not measured.
  float grey_depth_gap_rad = 0.0f;
};

struct AlignmentResult {
  Eigen::Isometry3d T_ref_cur = Eigen::Isometry3d::Identity();  // the (refined) hypothesis
  int sampled = 0;                                              // reference points tried
  int associated = 0;  // landed inside the current image on a surface with a normal
  int inliers = 0;     // ... and agreed within the residual and normal gates
  double rms_m = 0;    // point-to-plane RMS over the inliers
  double ncc = 0;      // normalised cross-correlation of the inliers' grey values, [-1, 1]
  double ref_intensity_std = 0;  // of the inliers' reference grey values: is there texture?
  int constrained = 0;           // directions (of 6) the geometry fixed in the last step
  int depth_constrained = 0;     // ... that depth alone fixed (the rest needed grey values)
  int confirmed = 0;             // weak directions the data left at the hypothesis' value
  bool weak_confirmed[6] = {};   // which of weak_axes' columns those are
  // The weak directions of the last step, as columns: unit twists [rotation * mean depth,
  // translation], so that a step of s along one moves the surface about s metres.
  Eigen::Matrix<double, 6, 6> weak_axes = Eigen::Matrix<double, 6, 6>::Zero();
  int weak_count = 0;
  int steps = 0;  // Gauss-Newton steps taken, depth and grey-value passes
  // Of align with earlier results: the index of the one this refinement reached (whose result
  // this is), or -1.
  int joined = -1;
  // Where depth alone fixed all six directions, how far apart the poses lie that depth alone and
  // grey values alone fit best (rotation in rad, translation in m; grey values stepped from the
  // polished pose to their optimum): 0 when the sensors agree, more when they measured
  // different motions (colour and depth taken apart in time, motion blur). Within the grey
  // values' reach, about 1 deg at 320x240 (test: within 0.1 deg up to 1 deg); beyond it, low.
  double grey_depth_gap_rad = 0;
  double grey_depth_gap_m = 0;
  // The estimate's spread along the directions the last step fixed, from its normal equations
  // and weighted residuals (sigma^2 H^-1; the root of the trace of its rotation and translation
  // blocks): rad and m. 0 before a step.
  double sigma_rotation_rad = 0;
  double sigma_translation_m = 0;
  // Depth's own normalised Hessian at the last step: its eigenvalues, ascending.
  Eigen::Matrix<double, 6, 1> depth_eigenvalues = Eigen::Matrix<double, 6, 1>::Zero();
  // The system the last step solved (depth, with the grey values when they took part): its
  // eigenvalues, ascending; `constrained` counts those that reach min_eigenvalue.
  Eigen::Matrix<double, 6, 1> eigenvalues = Eigen::Matrix<double, 6, 1>::Zero();
  // The current normals' noise: the variance of one of a normal's two components across the
  // surface, estimated as a quarter of the mean squared difference between the inliers' current
  // normals and their warped reference normals (two draws of the same noise, two components
  // each). A free direction of the geometry gets about this eigenvalue from the noise alone.
  double normal_noise_var = 0;
  // Whether a direction left free is mostly a rotation, mostly a translation.
  bool free_rotation = false;
  bool free_translation = false;
  // inliers / associated, and associated / sampled (0 when nothing was sampled).
  double inlierFraction() const { return associated ? double(inliers) / associated : 0.0; }
  double overlapFraction() const { return sampled ? double(associated) / sampled : 0.0; }
};

// Owns scratch so that repeated calls do not allocate.
class DepthAligner {
 public:
  // map_camera: the camera of the current normal map (already subsampled), with distortion.
  // T_ref_cur: the hypothesis, the current camera's pose in the reference camera's frame.
  AlignmentResult align(const SurfaceSample& ref, const AlignmentTarget& cur,
                        const Camera& map_camera, const Eigen::Isometry3d& T_ref_cur,
                        const AlignmentParams& params);
  // The same, ending as soon as the refinement comes within params.join_m of one of `earlier`
  // (results of align on the same sample and target): that result is returned, `joined` its
  // index. On a frame where several hypotheses reach one minimum, the later ones stop there.
  AlignmentResult align(const SurfaceSample& ref, const AlignmentTarget& cur,
                        const Camera& map_camera, const Eigen::Isometry3d& T_ref_cur,
                        const AlignmentParams& params, const AlignmentResult* const* earlier,
                        int earlier_count);
  // The same, building the target first (for a single hypothesis; several against one frame
  // should share one buildAlignmentTarget).
  AlignmentResult align(const SurfaceSample& ref, const NormalMap& cur,
                        const std::vector<float>& cur_intensity, const Camera& map_camera,
                        const Eigen::Isometry3d& T_ref_cur, const AlignmentParams& params);
  // A further joint pass from `from` (a result of align) that also steps along the directions
  // too weak to constrain, with eigenvalues of at least params.step_eigenvalue: grey values too
  // weak to verify a direction may still point the right way along it (a fast turn over one
  // plane). Returns `from` unless the grey values then agree better while the geometry does not
  // object (inliers within step_inlier_slack, no larger surface residual); weak directions stay
  // unverified.
  AlignmentResult refineAlongWeakDirections(const SurfaceSample& ref, const AlignmentTarget& cur,
                                            const Camera& map_camera, const AlignmentResult& from,
                                            const AlignmentParams& params);
  // From T_ref_cur, aligned on the pyramid's coarsest level first, then on each finer one, then
  // on `cur` itself (the pyramid built from it): a wider reach than one level's, for a motion
  // that left the hypothesis outside the data's basin at full resolution. The coarse levels'
  // association gate grows with their pixel size (AlignmentParams::coarse_gate_growth): with
  // the fine gate a start a fast turn left 10 deg off keeps too few points to move.
  AlignmentResult alignCoarseToFine(const SurfaceSample& ref, const AlignmentTarget& cur,
                                    const Camera& map_camera, const AlignmentPyramid& pyramid,
                                    const Eigen::Isometry3d& T_ref_cur,
                                    const AlignmentParams& params);
  // Of the weak directions of `result` (of align), those along which the grey values agree no
  // worse (NCC) with its pose moved params.confirm_shift_m either way, and how many of them were
  // confirmed: a would-be step from a linearisation cannot see a pose beyond the grey values'
  // reach, where their gradient has faded, and a value the check did not fix (the method's, a
  // confirmed one) is worth something only where the data tell the pose apart.
  struct Untold {
    int directions = 0;
    int confirmed = 0;
  };
  Untold untoldWeakDirections(const SurfaceSample& ref, const AlignmentTarget& cur,
                              const Camera& map_camera, const AlignmentResult& result,
                              const AlignmentParams& params);
  // Whether the direction that the grey values fix where depth leaves it weak, fixed least, is
  // one they cannot tell: with the pose moved params.confirm_shift_m either way along
  // it and the other directions fitted again from there, the grey values agree no worse (NCC).
  // Stripes fix little along themselves, yet enough for an eigenvalue bound; refitting the rest
  // takes out what a shift mixes in (a turn about the optical axis) and changes the stripes.
  bool greyFixedDirectionUntold(const SurfaceSample& ref, const AlignmentTarget& cur,
                                const Camera& map_camera, const AlignmentResult& result,
                                const AlignmentParams& params, Eigen::Matrix<double, 6, 1>* axis);
  // Room for samples of up to `points` points, so that steady state never allocates.
  void reserve(size_t points);

 private:
  // The earlier results align is to join (none outside that call), and the one reached.
  const AlignmentResult* const* join_ = nullptr;
  int join_count_ = 0;
  int joined_ = -1;
  // Whether T_cur_ref lies within join_m of one of join_ (then joined_ is its index).
  bool reachedEarlier(const Eigen::Isometry3d& T_cur_ref, double depth_scale, double join_m);
  // Which normal equations a pass over the sample fills.
  enum class Rows { kNone, kDepth, kDepthAndGrey, kGrey };
  // One pass over the sample at T_cur_ref: fills the normal equations asked for and the result's
  // counts, RMS and NCC.
  void evaluate(const SurfaceSample& ref, const AlignmentTarget& cur, const Camera& map_camera,
                const Eigen::Isometry3d& T_cur_ref, const AlignmentParams& params,
                double depth_scale, Rows rows, AlignmentResult* result);

  // Where grey values alone fit best, from T_both (the pose after the grey-value polish), against
  // T_depth (depth's own optimum): res->grey_depth_gap_rad and _m.
  void measureGreyDepthGap(const SurfaceSample& ref, const AlignmentTarget& cur,
                           const Camera& map_camera, const AlignmentParams& params,
                           double depth_scale, const Eigen::Isometry3d& T_depth,
                           const Eigen::Isometry3d& T_both, AlignmentResult* res);
  // Up to `iterations` steps from *T_cur_ref, updated in place.
  void gaussNewton(const SurfaceSample& ref, const AlignmentTarget& cur, const Camera& map_camera,
                   const AlignmentParams& params, double depth_scale, bool photometric,
                   int iterations, Eigen::Isometry3d* T_cur_ref,
                   Eigen::Matrix<double, 6, 1>* weak_moved, AlignmentResult* result,
                   const Eigen::Matrix<double, 6, 1>* held_axis = nullptr);
  // J^T W J and J^T W r, of one kind of residual.
  struct NormalEquations {
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    double rr = 0;  // the weighted residuals' squares summed
  };
  // Rows of one kind of residual, each [J, r] times the square root of its weight, summed into
  // normal equations by one matrix product: per row, an outer product into the 36 sums costs
  // more than the whole product does.
  class WeightedRows {
   public:
    void reserve(size_t rows) { data_.resize(rows * kWidth); }
    void clear() { count_ = 0; }
    size_t size() const { return count_; }
    // Residual r with the model's derivative direction d (a normal, or a grey gradient): the
    // Jacobian row is [p x d / depth_scale, d].
    void add(const Eigen::Vector3f& p, const Eigen::Vector3f& d, float r, float w,
             float inverse_depth_scale);
    void sum(NormalEquations* out) const;

   private:
    static constexpr size_t kWidth = 8;  // J, r, padding
    std::vector<float> data_;
    size_t count_ = 0;
  };
  // Every sample point at T_cur_ref = (R, t): its camera-frame point, image position and target
  // pixel (-1 when behind the camera or outside the image), into warped_ and pixel_.
  void warp(const SurfaceSample& ref, const AlignmentTarget& cur, const Camera& map_camera,
            const Eigen::Matrix3f& R, const Eigen::Vector3f& t);

  struct WarpedPoint {
    Eigen::Vector3f point;
    float u, v;
  };
  std::vector<WarpedPoint> warped_;
  std::vector<int> pixel_;

  AlignmentTarget own_target_;  // for the single-hypothesis align
  WeightedRows depth_rows_, grey_rows_;
  NormalEquations depth_, grey_;    // point-to-plane rows; grey-value rows
  double gain_ = 1.0, bias_ = 0.0;  // exposure change, estimated on the previous pass
  // The pose grey_ was built at by this align call's passes, if any.
  std::optional<Eigen::Isometry3d> grey_pose_;
};

}  // namespace nidevo

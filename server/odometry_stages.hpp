#pragma once
// The frame pipeline's work for one session: decode + normal map, rotation, translation and the
// answer, with the per-frame metrics. The session builds it once its config is known.
#include <memory>

#include "frame_decoder.hpp"
#include "frame_pipeline.hpp"
#include "nidevo/odometry/odometry.hpp"
#include "server_metrics.hpp"

namespace nidevo::server {

class OdometryStages final : public FrameStages {
 public:
  // Poses are reported as world_from_first * the odometry's (the session's initial pose).
  OdometryStages(std::shared_ptr<const FrameDecoder> decoder, std::unique_ptr<Odometry> odometry,
                 ServerMetrics* metrics,
                 const Eigen::Isometry3d& world_from_first = Eigen::Isometry3d::Identity());

  void prepare(FrameJob* job) override;
  void rotate(FrameJob* job) override;
  void translate(FrameJob* job) override;

 private:
  void observe(const FrameJob& job, const PoseEstimate& pose, double total_s);

  std::shared_ptr<const FrameDecoder> decoder_;
  std::unique_ptr<Odometry> odometry_;
  ServerMetrics* metrics_;
  Eigen::Isometry3d world_from_first_;
};

}  // namespace nidevo::server

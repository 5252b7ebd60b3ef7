// OpenCV-contrib's rgbd odometries (4.6 API, cv::rgbd), default parameters, camera matrix only.
// Each frame's OdometryFrame is prepared once (all caches) and reused as the next source's
// destination.
#include <opencv2/rgbd.hpp>

#include "method.hpp"

namespace nidevo::bench {

namespace {

class OpenCvMethod final : public FrameToFrameMethod {
 public:
  explicit OpenCvMethod(std::string type) : type_(std::move(type)) {}
  std::string name() const override { return "opencv_" + type_; }

 protected:
  void configure(const Camera& camera) override {
    const cv::Mat K =
        (cv::Mat_<double>(3, 3) << camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
    if (type_ == "FastICPOdometry")
      odometry_ = cv::rgbd::FastICPOdometry::create(K);
    else
      odometry_ = cv::rgbd::Odometry::create(type_);
    odometry_->setCameraMatrix(K);
    previous_.release();
  }
  void prepare(const RgbdFrame& frame) override {
    const cv::Mat gray(frame.gray.height, frame.gray.width, CV_8UC1,
                       const_cast<uint8_t*>(frame.gray.data.data()));
    const cv::Mat depth(frame.depth.height, frame.depth.width, CV_32FC1,
                        const_cast<float*>(frame.depth.data.data()));
    current_ = cv::rgbd::OdometryFrame::create(gray.clone(), depth.clone());
    odometry_->prepareFrameCache(current_, cv::rgbd::OdometryFrame::CACHE_ALL);
  }
  bool motionToPrevious(Eigen::Isometry3d* T_prev_cur) override {
    cv::Mat Rt;
    // dst_p = Rt * src_p with src = current, dst = previous: Rt is T_prev_cur.
    if (!odometry_->compute(current_, previous_, Rt)) return false;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) T_prev_cur->matrix()(r, c) = Rt.at<double>(r, c);
    return true;
  }
  void advance() override { previous_ = current_; }

 private:
  std::string type_;
  cv::Ptr<cv::rgbd::Odometry> odometry_;
  cv::Ptr<cv::rgbd::OdometryFrame> current_, previous_;
};

}  // namespace

void addOpenCvPeers(std::vector<std::unique_ptr<Method>>* methods) {
  for (const char* type : {"RgbdOdometry", "ICPOdometry", "RgbdICPOdometry", "FastICPOdometry"})
    methods->push_back(std::make_unique<OpenCvMethod>(type));
}

}  // namespace nidevo::bench

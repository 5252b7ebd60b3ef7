#include "nidevo/eval/trajectory_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace nidevo {

namespace {

constexpr int kPanel = 560;
constexpr int kMargin = 40;

void drawPanel(cv::Mat& img, int x0, const std::vector<Eigen::Vector3d>& ref,
               const std::vector<Eigen::Vector3d>& est, int ax, int ay, const std::string& name) {
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (const auto* pts : {&ref, &est}) {
    for (const auto& p : *pts) {
      lo[0] = std::min(lo[0], p[ax]);
      hi[0] = std::max(hi[0], p[ax]);
      lo[1] = std::min(lo[1], p[ay]);
      hi[1] = std::max(hi[1], p[ay]);
    }
  }
  const double span = std::max({hi[0] - lo[0], hi[1] - lo[1], 1e-3}) * 1.1;
  const double cxw = (lo[0] + hi[0]) / 2, cyw = (lo[1] + hi[1]) / 2;
  const double scale = (kPanel - 2 * kMargin) / span;
  auto to_px = [&](const Eigen::Vector3d& p) {
    return cv::Point(int(std::lround(x0 + kPanel / 2 + (p[ax] - cxw) * scale)),
                     int(std::lround(kPanel / 2 + 20 - (p[ay] - cyw) * scale)));
  };
  cv::rectangle(img, cv::Rect(x0 + 10, 30, kPanel - 20, kPanel - 20), cv::Scalar(200, 200, 200));
  auto polyline = [&](const std::vector<Eigen::Vector3d>& pts, cv::Scalar colour, int width) {
    for (size_t i = 1; i < pts.size(); ++i) {
      cv::line(img, to_px(pts[i - 1]), to_px(pts[i]), colour, width, cv::LINE_AA);
    }
  };
  polyline(ref, cv::Scalar(90, 90, 90), 2);
  polyline(est, cv::Scalar(200, 80, 20), 1);
  // A scale bar of a round length.
  const double bar_m = std::pow(10.0, std::floor(std::log10(span / 3)));
  const int bar_px = int(bar_m * scale);
  const int by = kPanel - 5;
  cv::line(img, {x0 + 30, by}, {x0 + 30 + bar_px, by}, cv::Scalar(0, 0, 0), 2);
  char label[64];
  std::snprintf(label, sizeof(label), "%g m", bar_m);
  cv::putText(img, label, {x0 + 36 + bar_px, by + 4}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(img, name, {x0 + 20, 50}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
}

}  // namespace

void writeTrajectoryPlot(const std::string& path, const std::vector<Eigen::Vector3d>& reference,
                         const std::vector<Eigen::Vector3d>& estimate, const std::string& title) {
  cv::Mat img(kPanel + 40, 2 * kPanel, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(img, title, {12, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  // Right-aligned, and clear of a long title (a long dataset path ran into it).
  const std::string legend = "grey: reference   blue: estimate (aligned)";
  int baseline = 0;
  const int title_end =
      12 + cv::getTextSize(title, cv::FONT_HERSHEY_SIMPLEX, 0.55, 1, &baseline).width;
  const int legend_width =
      cv::getTextSize(legend, cv::FONT_HERSHEY_SIMPLEX, 0.5, 1, &baseline).width;
  const int legend_x = std::max(title_end + 24, img.cols - 12 - legend_width);
  cv::putText(img, legend, {legend_x, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  drawPanel(img, 0, reference, estimate, 0, 2, "top view (x right, z up the page)");
  drawPanel(img, kPanel, reference, estimate, 0, 1, "side view (x right, y up the page)");
  if (!cv::imwrite(path, img)) throw std::runtime_error(path + ": cannot write PNG");
}

}  // namespace nidevo

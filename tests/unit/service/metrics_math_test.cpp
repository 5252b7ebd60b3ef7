// The load tester's statistics and the metrics text parser, on inputs with known answers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "load_test.hpp"
#include "metrics_scrape.hpp"
#include "prometheus/text_serializer.h"
#include "server_metrics.hpp"

namespace nidevo {
namespace {

TEST(LoadStatistics, NearestRankPercentiles) {
  std::vector<double> v;
  for (int i = 100; i >= 1; --i) v.push_back(i);  // 1..100, unsorted
  const client::LatencySummary s = client::summarize(v);
  EXPECT_EQ(s.count, 100u);
  EXPECT_EQ(s.p50, 50);
  EXPECT_EQ(s.p90, 90);
  EXPECT_EQ(s.p95, 95);
  EXPECT_EQ(s.p99, 99);
  EXPECT_EQ(s.max, 100);
  EXPECT_EQ(client::summarize({7}).p99, 7);
  EXPECT_EQ(client::summarize({}).count, 0u);
}

TEST(LoadStatistics, HistogramQuantileInterpolatesLikePrometheus) {
  const double inf = std::numeric_limits<double>::infinity();
  // 100 observations: 50 in (0, 1], 40 in (1, 2], 10 in (2, 4].
  const std::map<double, double> buckets = {{1, 50}, {2, 90}, {4, 100}, {inf, 100}};
  EXPECT_DOUBLE_EQ(client::histogramQuantile(0.5, buckets), 1.0);
  EXPECT_DOUBLE_EQ(client::histogramQuantile(0.7, buckets), 1.5);
  EXPECT_DOUBLE_EQ(client::histogramQuantile(0.95, buckets), 3.0);
  // Beyond the last finite bound: that bound.
  EXPECT_DOUBLE_EQ(client::histogramQuantile(0.99, {{1, 50}, {inf, 100}}), 1.0);
  EXPECT_EQ(client::histogramQuantile(0.5, {}), 0);
}

TEST(LoadStatistics, LatencyBreakdownTakesEachPartsMedianPerFrame) {
  // Three frames; the medians are per part, and outside_server is per frame (send to answer minus
  // that frame's server total), not the difference of the two medians.
  const std::vector<client::FrameTiming> frames = {
      {0.010, 0.007, 0.000, 0.001, 0.005},
      {0.030, 0.008, 0.001, 0.001, 0.006},
      {0.012, 0.011, 0.002, 0.002, 0.004},
  };
  const client::LatencyBreakdown b = client::breakdownOf(frames);
  EXPECT_EQ(b.count, 3u);
  EXPECT_DOUBLE_EQ(b.send_to_answer, 0.012);
  EXPECT_DOUBLE_EQ(b.server_total, 0.008);
  EXPECT_NEAR(b.outside_server, 0.003, 1e-12);  // of 0.003, 0.022, 0.001
  EXPECT_DOUBLE_EQ(b.queue, 0.001);
  EXPECT_DOUBLE_EQ(b.decode, 0.001);
  EXPECT_DOUBLE_EQ(b.stages, 0.005);
  EXPECT_NEAR(b.hand_offs, 0.001, 1e-12);  // of 0.001, 0.000, 0.003
  EXPECT_EQ(client::breakdownOf({}).count, 0u);
}

TEST(LoadStatistics, SessionPhasesSpreadOverThePeriodTheSameInEveryRun) {
  using Phase = client::LoadTestConfig::Phase;
  std::vector<double> phases;
  for (int k = 0; k < 8; ++k) {
    const double phase = client::sessionPhaseS(Phase::kRandom, k, 30);
    EXPECT_GE(phase, 0);
    EXPECT_LT(phase, 1.0 / 30);
    EXPECT_EQ(phase, client::sessionPhaseS(Phase::kRandom, k, 30));  // reproducible
    phases.push_back(phase);
    EXPECT_EQ(client::sessionPhaseS(Phase::kAligned, k, 30), 0);
    EXPECT_EQ(client::sessionPhaseS(Phase::kRandom, k, 0), 0);  // unpaced: no period
  }
  std::sort(phases.begin(), phases.end());
  EXPECT_EQ(std::unique(phases.begin(), phases.end()), phases.end());  // not all at once
  EXPECT_GT(phases.back() - phases.front(), 0.5 / 30);                 // spread over the period
}

TEST(MetricsText, ParsesSeriesAndSums) {
  const std::string text =
      "# HELP x_total a counter\n# TYPE x_total counter\n"
      "x_total{outcome=\"ok\"} 5\nx_total{outcome=\"error\"} 2\n"
      "x_total_other 100\nlatency_seconds_sum 0.25\nweird{label=\"a b}\"} 3\n";
  const auto m = client::parsePrometheusText(text);
  EXPECT_EQ(client::sumOf(m, "x_total"), 7);
  EXPECT_EQ(client::valueOf(m, "x_total{outcome=\"error\"}"), 2);
  EXPECT_EQ(client::valueOf(m, "latency_seconds_sum"), 0.25);
  EXPECT_EQ(client::valueOf(m, "weird{label=\"a b}\"}"), 3);
  EXPECT_EQ(client::valueOf(m, "absent"), 0);
}

TEST(ServerMetrics, RecordsWhatTheSessionReports) {
  server::ServerMetrics metrics("1.2.3");
  metrics.frame(server::FrameOutcome::kOk);
  metrics.frame(server::FrameOutcome::kOk);
  metrics.frame(server::FrameOutcome::kDropped);
  metrics.frameLatency(0.004);
  metrics.stage(server::Stage::kNormals, 0.002);
  metrics.psr(60);
  metrics.sessionEnded(grpc::StatusCode::INVALID_ARGUMENT);
  metrics.sessionEnded(99);  // unknown codes are folded into UNKNOWN
  metrics.activeSessions(+1);
  std::ostringstream out;
  prometheus::TextSerializer().Serialize(out, metrics.registry()->Collect());
  const auto m = client::parsePrometheusText(out.str());
  EXPECT_EQ(client::valueOf(m, "nidevo_frames_total{outcome=\"ok\"}"), 2);
  EXPECT_EQ(client::valueOf(m, "nidevo_frames_total{outcome=\"dropped\"}"), 1);
  EXPECT_EQ(client::sumOf(m, "nidevo_frames_total"), 3);
  EXPECT_EQ(client::valueOf(m, "nidevo_frame_latency_seconds_count"), 1);
  EXPECT_EQ(client::valueOf(m, "nidevo_frame_latency_seconds_bucket{le=\"0.005\"}"), 1);
  EXPECT_EQ(client::valueOf(m, "nidevo_frame_latency_seconds_bucket{le=\"0.003\"}"), 0);
  EXPECT_EQ(client::valueOf(m, "nidevo_stage_duration_seconds_count{stage=\"normals\"}"), 1);
  EXPECT_EQ(client::valueOf(m, "nidevo_frame_psr_count"), 1);
  EXPECT_EQ(client::valueOf(m, "nidevo_sessions_total{code=\"INVALID_ARGUMENT\"}"), 1);
  EXPECT_EQ(client::valueOf(m, "nidevo_sessions_total{code=\"UNKNOWN\"}"), 1);
  EXPECT_EQ(client::valueOf(m, "nidevo_active_sessions"), 1);
  EXPECT_EQ(client::valueOf(m, "nidevo_build_info{api=\"nidevo.v1\",version=\"1.2.3\"}"), 1);
}

TEST(ServerMetrics, CountsPoseChecksByTheHypothesisKept) {
  server::ServerMetrics metrics("1.2.3");
  metrics.poseCheck("method", true, 0.004);
  metrics.poseCheck("last pose", false, 0.02);
  metrics.poseCheck("prediction coarse to fine", true, 0.006);
  metrics.poseCheck("", false, 0.0);  // not checked (first frame, no depth): not counted
  std::ostringstream out;
  prometheus::TextSerializer().Serialize(out, metrics.registry()->Collect());
  const auto m = client::parsePrometheusText(out.str());
  EXPECT_EQ(client::valueOf(m, "nidevo_pose_checks_total{hypothesis=\"method\",result=\"passed\"}"),
            1);
  EXPECT_EQ(
      client::valueOf(m, "nidevo_pose_checks_total{hypothesis=\"last_pose\",result=\"failed\"}"),
      1);
  EXPECT_EQ(client::valueOf(
                m, "nidevo_pose_checks_total{hypothesis=\"coarse_to_fine\",result=\"passed\"}"),
            1);
  EXPECT_EQ(client::sumOf(m, "nidevo_pose_checks_total"), 3);
  EXPECT_EQ(client::valueOf(m, "nidevo_pose_check_residual_meters_count"), 3);
}

}  // namespace
}  // namespace nidevo

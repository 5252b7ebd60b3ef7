// /metrics of the real server: counters add up to the frames sent, promtool accepts the
// exposition, and a real Prometheus scrapes it.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include "metrics_scrape.hpp"
#include "server_process.hpp"
#include "service_fixtures.hpp"

namespace nidevo::test {
namespace {

using client::parseFrameEncoding;
using client::sumOf;
using client::valueOf;

// Streams 12 frames of which 2 are bad, then one session that is refused.
int driveServer(ServerProcess& server) {
  client::ChannelOptions options;
  options.target = server.target();
  client::Client client(options);
  const TestSequence seq = renderOffice(10, 1);
  const auto raw = parseFrameEncoding("raw");
  auto session = client.open(sessionFor(seq.camera, raw));
  v1::Frame frame;
  int sent = 0;
  for (size_t i = 0; i < 10; ++i) {
    client::encodeFrame(seq.frames[i], 5000, raw, &frame);
    frame.set_sequence(i);
    session->send(frame);
    ++sent;
    if (i == 4) {  // a repeated timestamp and a truncated image
      session->send(frame);
      frame.mutable_color()->resize(10);
      frame.set_timestamp(frame.timestamp() + 0.001);
      session->send(frame);
      sent += 2;
    }
  }
  EXPECT_TRUE(session->finish().ok());
  return sent;
}

TEST(Metrics, CountersAddUpToTheFramesSent) {
  ServerProcess server;
  const int sent = driveServer(server);
  // The client has its status before the server's OnDone frees the session: wait for that.
  auto scrape = [&] { return client::parsePrometheusText(client::httpGet(server.metricsUrl())); };
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (valueOf(scrape(), "nidevo_active_sessions") != 0 &&
         std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const auto m = scrape();
  EXPECT_EQ(sumOf(m, "nidevo_frames_total"), sent);
  EXPECT_EQ(valueOf(m, "nidevo_frames_total{outcome=\"error\"}"), 2);
  const double tracked = sent - 2;
  EXPECT_EQ(valueOf(m, "nidevo_frame_latency_seconds_count"), tracked);
  for (const char* stage : {"decode", "queue", "normals", "rotation", "translation"})
    EXPECT_EQ(
        valueOf(m, std::string("nidevo_stage_duration_seconds_count{stage=\"") + stage + "\"}"),
        tracked)
        << stage;
  EXPECT_GT(valueOf(m, "nidevo_frame_latency_seconds_sum"), 0);
  EXPECT_GE(valueOf(m, "nidevo_keyframes_total{kind=\"translation\"}"), 1);
  // Every tracked frame but the session's first is checked; a steady office passes.
  EXPECT_EQ(sumOf(m, "nidevo_pose_checks_total"), tracked - 1);
  EXPECT_GE(valueOf(m, "nidevo_pose_checks_total{hypothesis=\"method\",result=\"passed\"}"),
            tracked - 2);
  EXPECT_EQ(valueOf(m, "nidevo_pose_check_residual_meters_count"), tracked - 1);
  EXPECT_EQ(valueOf(m, "nidevo_sessions_total{code=\"OK\"}"), 1);
  EXPECT_EQ(valueOf(m, "nidevo_active_sessions"), 0);
  EXPECT_EQ(valueOf(m, "nidevo_build_info{api=\"nidevo.v1\",version=\"" NIDEVO_VERSION "\"}"), 1);
  // No series may carry a per-session label.
  for (const auto& entry : m)
    EXPECT_EQ(entry.first.find("session_id"), std::string::npos) << entry.first;
}

// The Prometheus client conventions' process metrics, read from the server's /proc entry.
TEST(Metrics, ProcessMetricsArePlausibleAndCpuTimeGrowsUnderLoad) {
  ServerProcess server;
  const auto before = client::parsePrometheusText(client::httpGet(server.metricsUrl()));
  driveServer(server);
  const auto after = client::parsePrometheusText(client::httpGet(server.metricsUrl()));
  EXPECT_GT(valueOf(after, "process_cpu_seconds_total"),
            valueOf(before, "process_cpu_seconds_total"));  // 10 tracked VGA frames
  EXPECT_GT(valueOf(after, "process_resident_memory_bytes"), 10e6);
  EXPECT_GE(valueOf(after, "process_virtual_memory_bytes"),
            valueOf(after, "process_resident_memory_bytes"));
  EXPECT_GE(valueOf(after, "process_open_fds"), 4);  // std streams and the listening sockets
  EXPECT_GE(valueOf(after, "process_max_fds"), valueOf(after, "process_open_fds"));
  const double now = double(std::chrono::duration_cast<std::chrono::seconds>(
                                std::chrono::system_clock::now().time_since_epoch())
                                .count());
  EXPECT_LE(valueOf(after, "process_start_time_seconds"), now + 1);
  EXPECT_GT(valueOf(after, "process_start_time_seconds"), now - 120);  // started by this test
}

TEST(Metrics, PromtoolAcceptsTheExposition) {
  ServerProcess server;
  driveServer(server);
  const std::string dir = makeTempDir();
  const std::string path = dir + "/metrics.txt";
  std::ofstream(path) << client::httpGet(server.metricsUrl());
  std::string output;
  const int status = runCommand("promtool check metrics < " + path, &output);
  EXPECT_EQ(status, 0) << output;
  std::filesystem::remove_all(dir);
}

TEST(Metrics, RealPrometheusScrapesTheFrameCounter) {
  ServerProcess server;
  const int sent = driveServer(server);
  const std::string dir = makeTempDir();
  const int port = freeTcpPort();
  std::ofstream(dir + "/prometheus.yml")
      << "global:\n  scrape_interval: 1s\n"
      << "scrape_configs:\n  - job_name: nidevo\n    static_configs:\n"
      << "      - targets: ['127.0.0.1:" << server.metricsPort() << "']\n";
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    freopen((dir + "/prometheus.log").c_str(), "w", stderr);
    const std::string config = "--config.file=" + dir + "/prometheus.yml";
    const std::string storage = "--storage.tsdb.path=" + dir + "/data";
    const std::string listen = "--web.listen-address=127.0.0.1:" + std::to_string(port);
    execlp("prometheus", "prometheus", config.c_str(), storage.c_str(), listen.c_str(),
           static_cast<char*>(nullptr));
    _exit(127);
  }
  const std::string query =
      "http://127.0.0.1:" + std::to_string(port) + "/api/v1/query?query=sum(nidevo_frames_total)";
  std::string answer;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    try {
      answer = client::httpGet(query, 2);
      if (answer.find("\"result\":[{") != std::string::npos) break;
    } catch (const std::exception&) {
      // not up yet
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  kill(pid, SIGTERM);
  waitpid(pid, nullptr, 0);
  EXPECT_NE(answer.find("\"" + std::to_string(sent) + "\""), std::string::npos)
      << "Prometheus answered: " << answer;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace nidevo::test

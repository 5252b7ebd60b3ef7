// The user-facing client programs against the real server: replay, load test, health, the
// Python example, and flags from the environment.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <thread>

#include "cpu_affinity.hpp"
#include "nidevo/io/trajectory.hpp"
#include "server_process.hpp"
#include "service_fixtures.hpp"

namespace nidevo::test {
namespace {

// A 40-frame synthetic TUM folder, written once for the whole test binary.
const std::string& syntheticFolder() {
  static const std::string folder = [] {
    const std::string dir = makeTempDir() + "/office";
    std::string output;
    const int rc = runCommand(std::string(NIDEVO_BIN_DIR "/nidevo-synth --frames 40 --texture low "
                                                         "--out ") +
                                  dir,
                              &output);
    if (rc != 0) throw std::runtime_error("nidevo-synth failed: " + output);
    return dir;
  }();
  return folder;
}

// The real Kinect clip in ../shared/data (its first 60 frames); empty where it is absent.
std::string realClipFlags() {
  const std::string folder = NIDEVO_SOURCE_DIR "/../shared/data/tum_fr1_rpy_first250";
  if (!std::filesystem::exists(folder + "/associations.txt")) return "";
  return " --dataset " + folder + " --camera tum_fr1 --max_frames 60";
}

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The first number after "key": in the load tester's JSON (one step).
double jsonNumber(const std::string& json, const std::string& key) {
  const size_t at = json.find("\"" + key + "\": ");
  if (at == std::string::npos) throw std::runtime_error("no " + key + " in " + json);
  return std::stod(json.substr(at + key.size() + 4));
}

// The "rmse" line of the APE table.
std::string apeRmse(const std::string& report) {
  const size_t ape = report.find("APE");
  const size_t rmse = report.find("rmse", ape);
  if (ape == std::string::npos || rmse == std::string::npos) return "";
  return report.substr(rmse, report.find('\n', rmse) - rmse);
}

TEST(ClientTools, ReplayWritesTheOfflineTrajectory) {
  ServerProcess server;
  const std::string dir = makeTempDir();
  std::string offline_out, replay_out;
  ASSERT_EQ(runCommand(NIDEVO_BIN_DIR "/nidevo-run --dataset " + syntheticFolder() + " --out " +
                           dir + "/offline.txt",
                       &offline_out),
            0)
      << offline_out;
  for (const char* encoding : {"png", "raw"}) {
    SCOPED_TRACE(encoding);
    ASSERT_EQ(runCommand(NIDEVO_BIN_DIR "/nidevo-client replay --target " + server.target() +
                             " --dataset " + syntheticFolder() + " --encoding " + encoding +
                             " --out " + dir + "/replay.txt --plot " + dir + "/replay.png",
                         &replay_out),
              0)
        << replay_out;
    EXPECT_NE(replay_out.find("40 frames sent, 40 answered"), std::string::npos) << replay_out;
    // Lossless encodings: the server sees the offline tool's exact frames, so the poses agree
    // to the last bits the quaternion round trip through the API keeps.
    const Trajectory offline = readTumTrajectory(dir + "/offline.txt");
    const Trajectory replay = readTumTrajectory(dir + "/replay.txt");
    ASSERT_EQ(replay.size(), offline.size());
    for (size_t i = 0; i < offline.size(); ++i) {
      EXPECT_EQ(replay[i].timestamp, offline[i].timestamp);
      EXPECT_LT((replay[i].translation - offline[i].translation).norm(), 1e-12) << i;
      EXPECT_LT(replay[i].rotation.angularDistance(offline[i].rotation), 1e-9) << i;
    }
    EXPECT_FALSE(apeRmse(replay_out).empty()) << replay_out;
    EXPECT_EQ(apeRmse(replay_out), apeRmse(offline_out));
    EXPECT_TRUE(std::filesystem::exists(dir + "/replay.png"));
  }
  std::filesystem::remove_all(dir);
}

TEST(ClientTools, LoadTestClosesItsAccountingAndReportsPercentiles) {
  ServerProcess server;
  const std::string dir = makeTempDir();
  std::string out;
  const int rc = runCommand(NIDEVO_BIN_DIR "/nidevo-client load --target " + server.target() +
                                " --sessions 3 --warmup_s 1 --duration_s 3 --frames 20 "
                                "--encoding raw --metrics_url " +
                                server.metricsUrl() + " --json " + dir + "/load.json --csv " + dir +
                                "/load.csv",
                            &out);
  ASSERT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("p99 ms"), std::string::npos) << out;
  EXPECT_EQ(out.find("DOES NOT ADD UP"), std::string::npos) << out;
  const std::string json = readText(dir + "/load.json");
  EXPECT_NE(json.find("\"accounting_closed\": true"), std::string::npos) << json;
  EXPECT_NE(json.find("\"sessions_ended\": {\"OK\": 3}"), std::string::npos) << json;
  // The server counted exactly what the tester sent.
  const size_t sent_at = json.find("\"sent\": ");
  const size_t frames_at = json.find("\"frames\": ");
  ASSERT_NE(sent_at, std::string::npos);
  ASSERT_NE(frames_at, std::string::npos);
  EXPECT_EQ(std::stol(json.substr(sent_at + 8)), std::stol(json.substr(frames_at + 10))) << json;
  // Paced at 30 Hz per session for 1 + 3 s: never faster. Under BLOCK a slow server takes fewer
  // (a lower bound would assert this machine's speed: 124 of 360 on a day it ran 4.5x slower).
  const long sent = std::stol(json.substr(sent_at + 8));
  EXPECT_GT(sent, 3);
  EXPECT_LE(sent, 3 * 30 * 4 * 11 / 10);
  // The server's CPU time over the step, from its process_cpu_seconds_total.
  EXPECT_GT(jsonNumber(json, "cpu_s_per_tracked_frame"), 0) << json;
  EXPECT_NE(out.find("ms per tracked frame"), std::string::npos) << out;
  const size_t p50_at = json.find("\"p50\": ");
  EXPECT_GT(std::stod(json.substr(p50_at + 7)), 0.0);
  // Send to answer taken apart with the server's timings: the server's interval lies inside the
  // client's, and the stages inside the server's.
  EXPECT_NE(out.find("outside the server"), std::string::npos) << out;
  const double server_total = jsonNumber(json, "server_total");
  EXPECT_GT(jsonNumber(json, "outside_server"), 0) << json;
  EXPECT_GT(server_total, 0) << json;
  EXPECT_LT(server_total, jsonNumber(json, "send_to_answer")) << json;
  EXPECT_GT(jsonNumber(json, "stages"), 0) << json;
  EXPECT_LE(jsonNumber(json, "stages"), server_total) << json;
  const std::string csv = readText(dir + "/load.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 2) << csv;  // header + one step
  std::filesystem::remove_all(dir);
}

// Many streams on one HTTP/2 connection, the tester pinned to one CPU and saying what it cost.
TEST(ClientTools, LoadTestOnOneSharedChannelPinnedToACpu) {
  ServerProcess server;
  const std::string dir = makeTempDir();
  std::string out;
  const std::string load = NIDEVO_BIN_DIR "/nidevo-client load --target " + server.target() +
                           " --sessions 3 --warmup_s 0 --duration_s 2 --frames 10 --encoding raw";
  const std::string cpu = std::to_string(client::allowedCpus().front());
  ASSERT_EQ(
      runCommand(load + " --shared_channel --cpus " + cpu + " --json " + dir + "/load.json", &out),
      0)
      << out;
  EXPECT_NE(out.find("pinned to CPUs " + cpu + "\n"), std::string::npos) << out;
  EXPECT_NE(out.find("one shared channel"), std::string::npos) << out;
  EXPECT_NE(out.find("closed OK x3"), std::string::npos) << out;
  const std::string json = readText(dir + "/load.json");
  EXPECT_GT(jsonNumber(json, "tester_cpu_s"), 0) << json;
  EXPECT_GT(jsonNumber(json, "step_s"), 1.9) << json;
  EXPECT_NE(runCommand(load + " --cpus 0-x", &out), 0);
  EXPECT_NE(out.find("--cpus: '0-x'"), std::string::npos) << out;
  EXPECT_NE(runCommand(load + " --session_phase sometimes", &out), 0);
  EXPECT_NE(out.find("--session_phase: 'random' or 'aligned', got 'sometimes'"), std::string::npos)
      << out;
  std::filesystem::remove_all(dir);
}

// Three sessions as fast as the client can send against one worker: far beyond what it tracks.
TEST(ClientTools, LoadTestUnderOverloadLatestAnswersEveryFrameAndBlockDropsNone) {
  ServerProcess server({"--workers=1"});
  const std::string dir = makeTempDir();
  for (const std::string policy : {"latest", "block"}) {
    std::string out;
    const std::string json_path = dir + "/" + policy + ".json";
    const int rc = runCommand(NIDEVO_BIN_DIR "/nidevo-client load --target " + server.target() +
                                  " --sessions 3 --session_rate 0 --warmup_s 1 --duration_s 3 "
                                  "--frames 20 --encoding raw --queue_capacity 1 --policy " +
                                  policy + " --json " + json_path,
                              &out);
    ASSERT_EQ(rc, 0) << policy << ": " << out;
    const std::string json = readText(json_path);
    EXPECT_NE(json.find("\"accounting_closed\": true"), std::string::npos) << json;
    EXPECT_NE(json.find("\"sessions_ended\": {\"OK\": 3}"), std::string::npos) << json;
    EXPECT_EQ(jsonNumber(json, "unanswered"), 0) << policy << ": " << json;
    EXPECT_EQ(jsonNumber(json, "error"), 0) << policy << ": " << json;
    EXPECT_GT(jsonNumber(json, "ok"), 0) << policy << ": " << json;
    if (policy == "latest") {
      EXPECT_GT(jsonNumber(json, "dropped"), 0) << json;  // old frames gave way to new ones
    } else {
      EXPECT_EQ(jsonNumber(json, "dropped"), 0) << json;
    }
  }
  std::filesystem::remove_all(dir);
}

TEST(ClientTools, HealthExitCodeFollowsTheServer) {
  std::string out;
  {
    ServerProcess server;
    EXPECT_EQ(runCommand(NIDEVO_BIN_DIR "/nidevo-client health --target " + server.target(), &out),
              0);
    EXPECT_NE(out.find("SERVING"), std::string::npos);
    EXPECT_EQ(runCommand(NIDEVO_BIN_DIR "/nidevo-client info --target " + server.target(), &out),
              0);
    EXPECT_NE(out.find("nidevo.v1"), std::string::npos) << out;
  }
  EXPECT_EQ(runCommand(NIDEVO_BIN_DIR "/nidevo-client health --connect_timeout_s 1 --target "
                                      "127.0.0.1:" +
                           std::to_string(freeTcpPort()),
                       &out),
            1);
  EXPECT_NE(out.find("UNAVAILABLE"), std::string::npos) << out;
}

// Lines of a TUM trajectory file that is still being written.
size_t poseLines(const std::string& path) {
  std::ifstream in(path);
  size_t n = 0;
  for (std::string line; std::getline(in, line);) n += !line.empty() && line[0] != '#';
  return n;
}

double apeRmseValue(const std::string& report) {
  const std::string line = apeRmse(report);
  return line.empty() ? -1 : std::stod(line.substr(line.find_first_of("0123456789")));
}

TEST(ClientTools, ReplayReconnectsAfterTheServerIsKilledAndKeepsTheWorldFrame) {
  const std::string clip = realClipFlags();
  if (clip.empty()) GTEST_SKIP() << "no ../shared/data/tum_fr1_rpy_first250";
  const std::string dir = makeTempDir();
  const std::string replay =
      NIDEVO_BIN_DIR "/nidevo-client replay --encoding raw --rate 30 --target ";
  const int port = freeTcpPort();
  const std::string address = "--address=127.0.0.1:" + std::to_string(port);
  std::string uninterrupted;
  {
    ServerProcess server({address});
    ASSERT_EQ(runCommand(replay + server.target() + clip + " --out " + dir + "/whole.txt",
                         &uninterrupted),
              0)
        << uninterrupted;
  }
  std::string out;
  int exit_code = -1;
  {
    auto first = std::make_unique<ServerProcess>(std::vector<std::string>{address});
    const std::string trajectory = dir + "/interrupted.txt";
    std::thread client([&] {
      exit_code = runCommand(replay + first->target() + clip + " --out " + trajectory, &out);
    });
    // Poses are written as they arrive: kill the server once a third of them are in the file.
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (poseLines(trajectory) < 20 && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    first->signal(SIGKILL);
    first->waitExit(10);
    first.reset();
    ServerProcess second({address});
    client.join();
    ASSERT_EQ(exit_code, 0) << out;
    EXPECT_NE(out.find("replay: 60 frames sent, 60 answered"), std::string::npos) << out;
    EXPECT_NE(out.find("reconnects: 1,"), std::string::npos) << out;
    EXPECT_NE(out.find("replay done: 60 frames sent, 60 answered, 60 poses written"),
              std::string::npos)
        << out;
    // Every frame answered once, in order, and no jump where the new session took over: each
    // pose stays near the uninterrupted run's pose of the same frame, rotation included.
    const Trajectory poses = readTumTrajectory(trajectory);
    const Trajectory reference = readTumTrajectory(dir + "/whole.txt");
    ASSERT_EQ(poses.size(), 60u);
    ASSERT_EQ(reference.size(), 60u);
    for (size_t i = 0; i < poses.size(); ++i) {
      if (i > 0) {
        EXPECT_GT(poses[i].timestamp, poses[i - 1].timestamp) << i;
      }
      EXPECT_EQ(poses[i].timestamp, reference[i].timestamp) << i;
      EXPECT_LT((poses[i].translation - reference[i].translation).norm(), 0.05) << i;
      EXPECT_LT(poses[i].rotation.angularDistance(reference[i].rotation), 2 * M_PI / 180) << i;
    }
  }
  const double whole = apeRmseValue(uninterrupted), interrupted = apeRmseValue(out);
  ASSERT_GT(whole, 0) << uninterrupted;
  EXPECT_LE(interrupted, 1.1 * whole)
      << "ATE " << interrupted << " m against " << whole << " m uninterrupted\n"
      << out;
  std::filesystem::remove_all(dir);
}

// Replays 120 synthetic frames at 40 Hz with `reconnect_flags` into `trajectory`, and kills the
// server for good once 20 poses are in the file. The replay's exit code; its output in *out.
int replayUntilTheServerDies(const std::string& reconnect_flags, const std::string& trajectory,
                             std::string* out) {
  int exit_code = -1;
  auto server = std::make_unique<ServerProcess>();
  std::thread client([&] {
    exit_code =
        runCommand(NIDEVO_BIN_DIR "/nidevo-client replay --frames 120 --rate 40 " +
                       reconnect_flags + " --out " + trajectory + " --target " + server->target(),
                   out);
  });
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (poseLines(trajectory) < 20 && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  server->signal(SIGKILL);
  client.join();
  return exit_code;
}

// The answers received are kept: the file holds every pose the replay's summary counts.
void expectThePosesReceivedWritten(const std::string& out, const std::string& trajectory) {
  const size_t written = poseLines(trajectory);
  EXPECT_GE(written, 20u);
  EXPECT_NE(out.find("answered, " + std::to_string(written) + " poses written to " + trajectory),
            std::string::npos)
      << out;
}

TEST(ClientTools, ReplayWithoutReconnectsSaysWhatItGotWhenTheServerDies) {
  const std::string dir = makeTempDir(), trajectory = dir + "/partial.txt";
  std::string out;
  EXPECT_EQ(replayUntilTheServerDies("--reconnect_attempts 0", trajectory, &out), 1) << out;
  EXPECT_NE(out.find("stream ended with UNAVAILABLE"), std::string::npos) << out;
  expectThePosesReceivedWritten(out, trajectory);
  std::filesystem::remove_all(dir);
}

TEST(ClientTools, ReplayGivesUpAfterItsReconnectAttemptsAndKeepsWhatItGot) {
  const std::string dir = makeTempDir(), trajectory = dir + "/partial.txt";
  std::string out;
  EXPECT_EQ(replayUntilTheServerDies("--reconnect_attempts 2 --reconnect_backoff_s 0.05",
                                     trajectory, &out),
            1)
      << out;
  EXPECT_NE(out.find("reconnect 2 of 2"), std::string::npos) << out;
  EXPECT_EQ(out.find("reconnect 3 of"), std::string::npos) << out;
  expectThePosesReceivedWritten(out, trajectory);
  std::filesystem::remove_all(dir);
}

TEST(ClientTools, ReplayEndsAtItsDeadlineWithTheStatus) {
  ServerProcess server;
  std::string out;
  EXPECT_EQ(runCommand(NIDEVO_BIN_DIR "/nidevo-client replay --frames 20 --pace --deadline_s 0.3 "
                                      "--target " +
                           server.target(),
                       &out),
            1);
  EXPECT_NE(out.find("stream ended with DEADLINE_EXCEEDED"), std::string::npos) << out;
}

TEST(ClientTools, FlagsComeFromTheEnvironmentAndTheCommandLineWins) {
  ServerProcess server({"--default_queue_capacity=2"},
                       {"NIDEVO_MAX_SESSIONS=3", "NIDEVO_DEFAULT_QUEUE_CAPACITY=9"});
  client::ChannelOptions options;
  options.target = server.target();
  client::Client client(options);
  v1::ServerInfo info;
  ASSERT_TRUE(client.serverInfo(&info).ok());
  EXPECT_EQ(info.max_sessions(), 3u);
  EXPECT_EQ(info.default_queue_capacity(), 2u);
}

TEST(ClientTools, TlsWithACaFile) {
  const std::string dir = makeTempDir();
  std::string out;
  ASSERT_EQ(runCommand("openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=localhost "
                       "-addext subjectAltName=DNS:localhost,IP:127.0.0.1 -keyout " +
                           dir + "/key.pem -out " + dir + "/cert.pem",
                       &out),
            0)
      << out;
  ServerProcess server(
      {"--tls_cert_file=" + dir + "/cert.pem", "--tls_key_file=" + dir + "/key.pem"});
  client::ChannelOptions options;
  options.target = server.target();
  options.tls = true;
  options.ca_file = dir + "/cert.pem";
  client::Client tls_client(options);
  bool serving = false;
  const grpc::Status status = tls_client.health("", &serving);
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_TRUE(serving);
  client::Client streaming(options);
  const StreamResult result =
      streamSequence(streaming, renderOffice(3, 1), client::parseFrameEncoding("raw"));
  EXPECT_TRUE(result.status.ok()) << result.status.error_message();
  EXPECT_EQ(result.responses.size(), 3u);
  options.tls = false;  // plaintext against a TLS port fails
  options.connect_timeout_s = 2;
  client::Client plain(options);
  EXPECT_FALSE(plain.health("", &serving).ok());
  std::filesystem::remove_all(dir);
}

TEST(ClientTools, ReflectionOnlyWithTheFlag) {
  const std::string dir = makeTempDir();
  std::string out;
  ASSERT_EQ(
      runCommand("/usr/bin/python3 -m grpc_tools.protoc -I" NIDEVO_SOURCE_DIR
                 "/tests/integration/proto --python_out=" +
                     dir + " --grpc_python_out=" + dir +
                     " " NIDEVO_SOURCE_DIR "/tests/integration/proto/reflection_v1alpha.proto",
                 &out),
      0)
      << out;
  const std::string list = "PYTHONPATH=" + dir +
                           " /usr/bin/python3 " NIDEVO_SOURCE_DIR
                           "/tests/integration/list_services.py ";
  {
    ServerProcess server({"--reflection"});
    ASSERT_EQ(runCommand(list + server.target(), &out), 0) << out;
    EXPECT_NE(out.find("nidevo.v1.OdometryService"), std::string::npos) << out;
    EXPECT_NE(out.find("grpc.health.v1.Health"), std::string::npos) << out;
  }
  {
    ServerProcess server;
    EXPECT_EQ(runCommand(list + server.target(), &out), 1) << out;
    EXPECT_NE(out.find("UNIMPLEMENTED"), std::string::npos) << out;
  }
  std::filesystem::remove_all(dir);
}

TEST(ClientTools, PythonClientGetsOnePosePerFrame) {
  const std::string dir = makeTempDir();
  std::string out;
  ASSERT_EQ(runCommand("/usr/bin/python3 -m grpc_tools.protoc -I" NIDEVO_SOURCE_DIR "/proto"
                       " --python_out=" +
                           dir + " --grpc_python_out=" + dir +
                           " " NIDEVO_SOURCE_DIR "/proto/nidevo/v1/odometry.proto",
                       &out),
            0)
      << out;
  ServerProcess server;
  ASSERT_EQ(runCommand("PYTHONPATH=" + dir +
                           " /usr/bin/python3 " NIDEVO_SOURCE_DIR
                           "/client/python/nidevo_stream.py --target " +
                           server.target() + " --folder " + syntheticFolder(),
                       &out),
            0)
      << out;
  // Same poses as the offline tool on the same files.
  std::string offline_out;
  ASSERT_EQ(runCommand(NIDEVO_BIN_DIR "/nidevo-run --dataset " + syntheticFolder() + " --out " +
                           dir + "/offline.txt",
                       &offline_out),
            0);
  const Trajectory offline = readTumTrajectory(dir + "/offline.txt");
  std::istringstream lines(out);
  std::string line;
  size_t n = 0;
  while (std::getline(lines, line)) {
    std::istringstream f(line);
    uint64_t sequence;
    double t, tx, ty, tz, qx, qy, qz, qw, psr;
    std::string status;
    ASSERT_TRUE(f >> sequence >> t >> status >> tx >> ty >> tz >> qx >> qy >> qz >> qw >> psr)
        << line;
    ASSERT_EQ(sequence, n);
    EXPECT_TRUE(status == "OK" || status == "DEGRADED") << line;
    EXPECT_NEAR(tx, offline[n].translation.x(), 1e-8);
    EXPECT_NEAR(tz, offline[n].translation.z(), 1e-8);
    ++n;
  }
  EXPECT_EQ(n, 40u) << out;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace nidevo::test

// The real nidevo-server binary on loopback, driven by the real client library.
#include <gtest/gtest.h>
#include <signal.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include "metrics_scrape.hpp"
#include "server_process.hpp"
#include "service_fixtures.hpp"

namespace nidevo::test {
namespace {

using client::Client;
using client::FrameEncoding;
using client::parseFrameEncoding;

client::ChannelOptions channelTo(const ServerProcess& server) {
  client::ChannelOptions options;
  options.target = server.target();
  options.connect_timeout_s = 10;
  return options;
}

void expectSamePoses(const std::vector<v1::TrackResponse>& responses,
                     const std::vector<PoseEstimate>& offline) {
  ASSERT_EQ(responses.size(), offline.size());
  for (size_t i = 0; i < offline.size(); ++i) {
    const auto& r = responses[i];
    EXPECT_EQ(r.sequence(), i);
    EXPECT_EQ(int(r.status()), int(offline[i].state) + 1) << "frame " << i << " " << r.reason();
    const Eigen::Isometry3d T = client::toIsometry(r.pose());
    EXPECT_LT((T.translation() - offline[i].T_world_cam.translation()).norm(), 1e-9)
        << "frame " << i;
    const Eigen::AngleAxisd dR(T.linear().transpose() * offline[i].T_world_cam.linear());
    EXPECT_LT(std::abs(dR.angle()), 1e-9) << "frame " << i;
    EXPECT_EQ(r.planes_used(), offline[i].planes_used) << "frame " << i;
    EXPECT_EQ(r.translation_keyframe(), offline[i].translation_keyframe) << "frame " << i;
  }
}

const TestSequence& office() {
  static const TestSequence sequence = renderOffice(40, 1);
  return sequence;
}

TEST(Service, PosesEqualTheOfflinePipeline) {
  ServerProcess server;
  Client client(channelTo(server));
  const auto offline = offlinePoses(office());
  for (const char* encoding : {"raw-f32", "raw", "png"}) {
    SCOPED_TRACE(encoding);
    // raw and png quantise depth to 1/5000 m; the reference sees the same quantised frames.
    TestSequence quantised = office();
    if (std::string(encoding) != "raw-f32")
      for (auto& f : quantised.frames)
        for (float& d : f.depth.data)
          d = d > 0 ? float(std::round(d * 5000.0)) * (1.f / 5000.f) : 0;
    const StreamResult result = streamSequence(client, quantised, parseFrameEncoding(encoding));
    ASSERT_TRUE(result.status.ok()) << result.status.error_message();
    expectSamePoses(result.responses, offlinePoses(quantised));
    for (const auto& r : result.responses) {
      EXPECT_GT(r.timings().total(), 0);
      EXPECT_GE(r.timings().total(), r.timings().normals() + r.timings().translation());
      // Every frame after the first carries the pose check that decided its status.
      if (r.sequence() == 0) continue;
      ASSERT_TRUE(r.has_check()) << r.sequence();
      EXPECT_FALSE(r.check().hypothesis().empty());
      if (r.status() == v1::FRAME_STATUS_OK) {
        EXPECT_TRUE(r.check().passed()) << r.sequence();
        EXPECT_GT(r.check().inlier_fraction(), 0.5) << r.sequence();
      }
    }
  }
  (void)offline;
}

TEST(Service, LargerHttp2WindowsAndFramesOnBothEndsCarryTheSamePoses) {
  // 8 MiB windows and 1 MiB HTTP/2 frames: a raw VGA frame crosses in one window, in a frame
  // or two, where gRPC's defaults (64 KiB, 16 KiB) need a window update every 64 KiB.
  ServerProcess server({"--http2_stream_window_bytes=8388608", "--http2_max_frame_bytes=1048576"});
  client::ChannelOptions channel = channelTo(server);
  channel.http2_stream_window_bytes = 8 << 20;
  channel.http2_max_frame_bytes = 1 << 20;
  Client client(channel);
  TestSequence quantised = renderOffice(12, 1);
  for (auto& f : quantised.frames)
    for (float& d : f.depth.data) d = d > 0 ? float(std::round(d * 5000.0)) * (1.f / 5000.f) : 0;
  const StreamResult result = streamSequence(client, quantised, parseFrameEncoding("raw"));
  ASSERT_TRUE(result.status.ok()) << result.status.error_message();
  expectSamePoses(result.responses, offlinePoses(quantised));
}

TEST(Service, AnInitialPoseSetsTheWorldFrameOfEveryPose) {
  ServerProcess server;
  Client client(channelTo(server));
  Eigen::Isometry3d world_from_first = Eigen::Isometry3d::Identity();
  world_from_first.linear() =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  world_from_first.translation() = Eigen::Vector3d(1.5, -2, 0.25);
  const auto offline = offlinePoses(office());
  const StreamResult result =
      streamSequence(client, office(), parseFrameEncoding("raw-f32"), world_from_first);
  ASSERT_TRUE(result.status.ok()) << result.status.error_message();
  ASSERT_EQ(result.responses.size(), offline.size());
  for (size_t i = 0; i < offline.size(); ++i) {
    const Eigen::Isometry3d expected = world_from_first * offline[i].T_world_cam;
    const Eigen::Isometry3d got = client::toIsometry(result.responses[i].pose());
    EXPECT_LT((got.translation() - expected.translation()).norm(), 1e-9) << i;
    EXPECT_LT(Eigen::AngleAxisd(got.rotation().transpose() * expected.rotation()).angle(), 1e-9)
        << i;
  }
}

TEST(Service, ConcurrentSessionsEachGetTheirOwnPoses) {
  ServerProcess server;
  std::vector<TestSequence> sequences;
  for (uint64_t seed = 1; seed <= 4; ++seed) sequences.push_back(renderOffice(30, seed));
  std::vector<StreamResult> results(4);
  std::vector<std::thread> threads;
  for (size_t k = 0; k < 4; ++k)
    threads.emplace_back([&, k] {
      Client client(channelTo(server));
      results[k] = streamSequence(client, sequences[k], parseFrameEncoding("raw-f32"));
    });
  for (auto& t : threads) t.join();
  for (size_t k = 0; k < 4; ++k) {
    SCOPED_TRACE("session " + std::to_string(k));
    ASSERT_TRUE(results[k].status.ok()) << results[k].status.error_message();
    expectSamePoses(results[k].responses, offlinePoses(sequences[k]));
  }
}

// Opens a stream, sends `request` as the first message and returns the final status.
grpc::Status firstMessageStatus(const ServerProcess& server, const v1::TrackRequest& request) {
  auto channel = grpc::CreateChannel(server.target(), grpc::InsecureChannelCredentials());
  auto stub = v1::OdometryService::NewStub(channel);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(20));
  auto stream = stub->Track(&context);
  stream->Write(request);
  v1::TrackResponse response;
  while (stream->Read(&response)) {
  }
  return stream->Finish();
}

v1::TrackRequest validConfig() {
  v1::TrackRequest request;
  auto* c = request.mutable_config();
  const Camera cam = office().camera;
  c->mutable_camera()->set_fx(cam.fx);
  c->mutable_camera()->set_fy(cam.fy);
  c->mutable_camera()->set_cx(cam.cx);
  c->mutable_camera()->set_cy(cam.cy);
  c->mutable_camera()->set_width(uint32_t(cam.width));
  c->mutable_camera()->set_height(uint32_t(cam.height));
  c->set_color_encoding(v1::COLOR_ENCODING_GRAY8);
  c->set_depth_encoding(v1::DEPTH_ENCODING_UINT16);
  c->set_depth_scale(5000);
  return request;
}

TEST(Service, MalformedSessionConfigsEndWithInvalidArgumentNamingTheField) {
  ServerProcess server;
  struct Case {
    const char* name;
    std::function<void(v1::TrackRequest*)> mutate;
    const char* field;
  };
  const Case cases[] = {
      {"frame first", [](v1::TrackRequest* r) { r->mutable_frame()->set_sequence(1); }, "config"},
      {"no camera", [](v1::TrackRequest* r) { r->mutable_config()->clear_camera(); },
       "config.camera"},
      {"zero fx", [](v1::TrackRequest* r) { r->mutable_config()->mutable_camera()->set_fx(0); },
       "fx"},
      {"zero width",
       [](v1::TrackRequest* r) { r->mutable_config()->mutable_camera()->set_width(0); },
       "config.camera.width"},
      {"absurd distortion",
       [](v1::TrackRequest* r) {
         r->mutable_config()->mutable_camera()->mutable_distortion()->set_k1(50);
       },
       "distortion"},
      {"unknown colour encoding",
       [](v1::TrackRequest* r) {
         r->mutable_config()->set_color_encoding(static_cast<v1::ColorEncoding>(42));
       },
       "config.color_encoding"},
      {"no depth encoding",
       [](v1::TrackRequest* r) {
         r->mutable_config()->set_depth_encoding(v1::DEPTH_ENCODING_UNSPECIFIED);
       },
       "config.depth_encoding"},
      {"no depth scale", [](v1::TrackRequest* r) { r->mutable_config()->set_depth_scale(0); },
       "config.depth_scale"},
      {"huge queue", [](v1::TrackRequest* r) { r->mutable_config()->set_queue_capacity(100000); },
       "config.queue_capacity"},
      {"initial pose not a rotation",
       [](v1::TrackRequest* r) { r->mutable_config()->mutable_initial_pose()->set_qw(2); },
       "config.initial_pose: the quaternion must be unit length"},
      {"initial pose not finite",
       [](v1::TrackRequest* r) {
         auto* p = r->mutable_config()->mutable_initial_pose();
         p->set_qw(1);
         p->set_tx(std::nan(""));
       },
       "config.initial_pose: every value must be finite"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    v1::TrackRequest request = validConfig();
    c.mutate(&request);
    const grpc::Status status = firstMessageStatus(server, request);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(status.error_message().find(c.field), std::string::npos) << status.error_message();
  }
  // The server is unharmed: a good session still works.
  Client client(channelTo(server));
  EXPECT_TRUE(streamSequence(client, renderOffice(3, 1), parseFrameEncoding("raw")).status.ok());
}

TEST(Service, BadFramesGetAnErrorAnswerAndTheSessionGoesOn) {
  ServerProcess server;
  Client client(channelTo(server));
  const TestSequence seq = renderOffice(6, 1);
  const FrameEncoding png = parseFrameEncoding("png");
  std::vector<v1::TrackResponse> responses;
  auto session = client.open(sessionFor(seq.camera, png),
                             [&](const v1::TrackResponse& r) { responses.push_back(r); });
  v1::Frame frame;
  client::encodeFrame(seq.frames[0], 5000, png, &frame);
  frame.set_sequence(0);
  ASSERT_TRUE(session->send(frame));
  frame.set_sequence(1);  // same timestamp again
  ASSERT_TRUE(session->send(frame));
  client::encodeFrame(seq.frames[1], 5000, png, &frame);
  frame.set_sequence(2);
  frame.set_color("not a png");
  ASSERT_TRUE(session->send(frame));
  client::encodeFrame(seq.frames[2], 5000, png, &frame);
  frame.set_sequence(3);
  {  // a 16-bit PNG of the wrong size
    TestSequence small = seq;
    RgbdFrame f;
    f.gray.resize(8, 8, 100);
    f.depth.resize(8, 8, 1.f);
    v1::Frame tiny;
    client::encodeFrame(f, 5000, png, &tiny);
    frame.set_depth(tiny.depth());
  }
  ASSERT_TRUE(session->send(frame));
  for (int i = 3; i < 6; ++i) {
    client::encodeFrame(seq.frames[size_t(i)], 5000, png, &frame);
    frame.set_sequence(uint64_t(i + 1));
    ASSERT_TRUE(session->send(frame));
  }
  const grpc::Status status = session->finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(responses.size(), 7u);
  std::map<uint64_t, v1::TrackResponse> by_sequence;
  for (const auto& r : responses) by_sequence[r.sequence()] = r;
  ASSERT_EQ(by_sequence.size(), 7u);
  EXPECT_EQ(by_sequence[0].status(), v1::FRAME_STATUS_OK);
  EXPECT_EQ(by_sequence[1].status(), v1::FRAME_STATUS_ERROR);
  EXPECT_NE(by_sequence[1].reason().find("frame.timestamp"), std::string::npos);
  EXPECT_EQ(by_sequence[2].status(), v1::FRAME_STATUS_ERROR);
  EXPECT_NE(by_sequence[2].reason().find("frame.color"), std::string::npos);
  EXPECT_EQ(by_sequence[3].status(), v1::FRAME_STATUS_ERROR);
  EXPECT_NE(by_sequence[3].reason().find("frame.depth"), std::string::npos);
  for (uint64_t s = 4; s <= 6; ++s) EXPECT_EQ(by_sequence[s].status(), v1::FRAME_STATUS_OK) << s;
}

TEST(Service, SessionLimitGivesResourceExhausted) {
  ServerProcess server({"--max_sessions=1"});
  Client client(channelTo(server));
  const TestSequence seq = renderOffice(2, 1);
  std::vector<v1::TrackResponse> first_responses;
  auto first = client.open(sessionFor(seq.camera, parseFrameEncoding("raw")));
  v1::Frame frame;
  client::encodeFrame(seq.frames[0], 5000, parseFrameEncoding("raw"), &frame);
  ASSERT_TRUE(first->send(frame));
  v1::TrackResponse response;
  ASSERT_TRUE(first->receive(&response));  // the first session is surely admitted now
  const grpc::Status second = firstMessageStatus(server, validConfig());
  EXPECT_EQ(second.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(second.error_message().find("limit of 1"), std::string::npos) << second.error_message();
  EXPECT_TRUE(first->finish().ok());
}

TEST(Service, OversizedMessageGivesResourceExhausted) {
  ServerProcess server({"--max_message_bytes=100000"});
  Client client(channelTo(server));
  const TestSequence seq = renderOffice(1, 1);
  auto session = client.open(sessionFor(seq.camera, parseFrameEncoding("raw-f32")));
  v1::Frame frame;  // 320x240 grey + float depth: 384 kB
  client::encodeFrame(seq.frames[0], 5000, parseFrameEncoding("raw-f32"), &frame);
  session->send(frame);
  const grpc::Status status = session->finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(status.error_message().find("larger than max"), std::string::npos)
      << status.error_message();
}

TEST(Service, IdleSessionEndsWithDeadlineExceeded) {
  ServerProcess server({"--idle_timeout_s=0.5"});
  Client client(channelTo(server));
  auto session = client.open(sessionFor(office().camera, parseFrameEncoding("raw")));
  const auto start = std::chrono::steady_clock::now();
  v1::TrackResponse response;
  EXPECT_FALSE(session->receive(&response));  // returns when the server ends the stream
  const double waited =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const grpc::Status status = session->finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  EXPECT_NE(status.error_message().find("idle"), std::string::npos);
  EXPECT_GT(waited, 0.4);
  EXPECT_LT(waited, 5.0);
}

int activeSessions(Client& client) {
  v1::ServerInfo info;
  EXPECT_TRUE(client.serverInfo(&info).ok());
  return int(info.active_sessions());
}

TEST(Service, VanishingClientFreesItsSessionPromptly) {
  ServerProcess server;
  Client client(channelTo(server));
  const TestSequence seq = renderOffice(4, 1);
  {
    auto session = client.open(sessionFor(seq.camera, parseFrameEncoding("raw")));
    v1::Frame frame;
    for (size_t i = 0; i < 4; ++i) {
      client::encodeFrame(seq.frames[i], 5000, parseFrameEncoding("raw"), &frame);
      frame.set_sequence(i);
      session->send(frame);
    }
    EXPECT_EQ(activeSessions(client), 1);
    session->cancel();
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (activeSessions(client) != 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(activeSessions(client), 0);
  const auto metrics = client::parsePrometheusText(client::httpGet(server.metricsUrl()));
  EXPECT_EQ(client::valueOf(metrics, "nidevo_sessions_total{code=\"CANCELLED\"}"), 1);
  EXPECT_EQ(client::valueOf(metrics, "nidevo_active_sessions"), 0);
  EXPECT_EQ(client::valueOf(metrics, "nidevo_queued_frames"), 0);
}

TEST(Service, LatestPolicyDropsOldFramesAndAnswersEveryOne) {
  ServerProcess server({"--workers=1"});
  Client client(channelTo(server));
  const TestSequence seq = renderOffice(10, 1);
  client::SessionOptions options = sessionFor(seq.camera, parseFrameEncoding("raw"));
  options.overload_policy = v1::OVERLOAD_POLICY_LATEST;
  options.queue_capacity = 1;
  std::vector<v1::TrackResponse> responses;
  auto session = client.open(options, [&](const v1::TrackResponse& r) { responses.push_back(r); });
  v1::Frame frame;
  const int sent = 100;
  for (int i = 0; i < sent; ++i) {  // far faster than one worker tracks
    client::encodeFrame(seq.frames[size_t(i % 10)], 5000, parseFrameEncoding("raw"), &frame);
    frame.set_sequence(uint64_t(i));
    frame.set_timestamp(i / 30.0);
    ASSERT_TRUE(session->send(frame));
  }
  ASSERT_TRUE(session->finish().ok());
  ASSERT_EQ(int(responses.size()), sent);
  int dropped = 0;
  std::set<uint64_t> seen;
  for (const auto& r : responses) {
    seen.insert(r.sequence());
    if (r.status() == v1::FRAME_STATUS_DROPPED) {
      ++dropped;
      EXPECT_NE(r.reason().find("LATEST"), std::string::npos);
    }
  }
  EXPECT_EQ(int(seen.size()), sent);
  EXPECT_GT(dropped, 0);
  EXPECT_EQ(responses.back().sequence(), uint64_t(sent - 1));  // the newest is always tracked
}

// Clients that misbehave in every way this test knows, all at once, next to one good session.
TEST(Service, MisbehavingClientsDoNotHarmAnotherSession) {
  ServerProcess server({"--max_sessions=6", "--idle_timeout_s=1"});
  const TestSequence seq = renderOffice(30, 2);
  StreamResult good;
  std::atomic<bool> good_done{false};
  std::thread good_thread([&] {
    Client client(channelTo(server));
    good = streamSequence(client, seq, parseFrameEncoding("raw-f32"));  // offline's exact frames
    good_done = true;
  });
  // The troublemakers start once the good session holds its slot: the session limit is shared
  // by design, and on a loaded machine their cancelled streams could otherwise fill it before
  // the server admits the good one.
  {
    Client probe(channelTo(server));
    const auto admitted_by = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (!good_done && activeSessions(probe) == 0 &&
           std::chrono::steady_clock::now() < admitted_by)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::atomic<int> rounds{0};
  std::vector<std::thread> troublemakers;
  for (int k = 0; k < 4; ++k)
    troublemakers.emplace_back([&, k] {
      Client client(channelTo(server));
      const FrameEncoding raw = parseFrameEncoding("raw");
      for (int round = 0; round < 5; ++round) {
        ++rounds;
        if (k == 0) {  // a malformed first message
          firstMessageStatus(server, v1::TrackRequest());
          continue;
        }
        std::unique_ptr<client::Session> session;
        try {
          session = client.open(sessionFor(seq.camera, raw));
        } catch (const std::exception&) {
          continue;  // refused at the session limit: fine
        }
        v1::Frame frame;
        client::encodeFrame(seq.frames[size_t(round)], 5000, raw, &frame);
        if (k == 1) frame.mutable_depth()->resize(7);  // garbage frames
        for (int i = 0; i < 3; ++i) {
          frame.set_sequence(uint64_t(i));
          frame.set_timestamp(round + i * 0.01);
          if (!session->send(frame)) break;
        }
        if (k == 2) {
          session->cancel();  // vanishes mid-stream
        } else if (k == 3) {
          v1::TrackResponse r;  // goes quiet until the idle timeout ends it
          while (session->receive(&r)) {
          }
          session->finish();
        } else {
          session->finish();
        }
      }
    });
  for (auto& t : troublemakers) t.join();
  good_thread.join();
  EXPECT_EQ(rounds.load(), 20);
  ASSERT_TRUE(good.status.ok()) << good.status.error_message();
  expectSamePoses(good.responses, offlinePoses(seq));
  Client client(channelTo(server));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (activeSessions(client) != 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(activeSessions(client), 0);
  EXPECT_TRUE(server.running());
}

TEST(Service, HealthAndServerInfo) {
  ServerProcess server({"--max_sessions=7"});
  Client client(channelTo(server));
  bool serving = false;
  ASSERT_TRUE(client.health("nidevo.v1.OdometryService", &serving).ok());
  EXPECT_TRUE(serving);
  ASSERT_TRUE(client.health("", &serving).ok());
  EXPECT_TRUE(serving);
  EXPECT_EQ(client.health("no.such.Service", &serving).error_code(), grpc::StatusCode::NOT_FOUND);
  v1::ServerInfo info;
  ASSERT_TRUE(client.serverInfo(&info).ok());
  EXPECT_EQ(info.api(), "nidevo.v1");
  EXPECT_EQ(info.max_sessions(), 7u);
  EXPECT_EQ(info.worker_threads(), 2u);
  EXPECT_EQ(info.color_encodings_size(), 5);
  EXPECT_EQ(info.depth_encodings_size(), 3);
}

TEST(Service, SigtermDrainsOpenStreamsAndReportsNotServing) {
  ServerProcess server({"--drain_timeout_s=20"});
  Client client(channelTo(server));
  const TestSequence seq = renderOffice(10, 1);
  const FrameEncoding raw = parseFrameEncoding("raw");
  std::atomic<int> answered{0};
  auto session =
      client.open(sessionFor(seq.camera, raw), [&](const v1::TrackResponse&) { ++answered; });
  v1::Frame frame;
  for (size_t i = 0; i < 5; ++i) {
    client::encodeFrame(seq.frames[i], 5000, raw, &frame);
    frame.set_sequence(i);
    ASSERT_TRUE(session->send(frame));
  }
  // Until the server answers, the stream may still sit in gRPC's buffers, not yet a session (a
  // slow sanitizer build showed that race); once answered, it is an open stream to drain.
  const auto answered_by = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (answered.load() < 5 && std::chrono::steady_clock::now() < answered_by)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_EQ(answered.load(), 5);
  server.signal(SIGTERM);
  bool serving = true;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (serving && std::chrono::steady_clock::now() < deadline) {
    client.health("nidevo.v1.OdometryService", &serving);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_FALSE(serving) << "health still SERVING after SIGTERM";
  EXPECT_EQ(firstMessageStatus(server, validConfig()).error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_TRUE(server.running()) << "the server must wait for the open stream";
  for (size_t i = 5; i < 10; ++i) {  // the open stream keeps working
    client::encodeFrame(seq.frames[i], 5000, raw, &frame);
    frame.set_sequence(i);
    ASSERT_TRUE(session->send(frame));
  }
  const grpc::Status status = session->finish();
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(answered.load(), 10);
  EXPECT_EQ(server.waitExit(10), 0);
}

TEST(Service, DrainDeadlineCancelsStreamsThatDoNotFinish) {
  ServerProcess server({"--drain_timeout_s=1"});
  Client client(channelTo(server));
  auto session = client.open(sessionFor(office().camera, parseFrameEncoding("raw")));
  // The stream counts as open once the server has made it a session.
  v1::ServerInfo info;
  const auto registered_by = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while ((!client.serverInfo(&info).ok() || info.active_sessions() < 1) &&
         std::chrono::steady_clock::now() < registered_by)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_EQ(info.active_sessions(), 1u);
  const auto start = std::chrono::steady_clock::now();
  server.signal(SIGTERM);
  EXPECT_EQ(server.waitExit(15), 0);
  const double took =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GT(took, 0.9);
  EXPECT_LT(took, 10.0);
  v1::TrackResponse response;
  EXPECT_FALSE(session->receive(&response));
  const grpc::Status status = session->finish();
  EXPECT_TRUE(status.error_code() == grpc::StatusCode::UNAVAILABLE ||
              status.error_code() == grpc::StatusCode::CANCELLED)
      << status.error_code() << " " << status.error_message();
}

}  // namespace
}  // namespace nidevo::test

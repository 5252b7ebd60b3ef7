// A bounded soak: many sessions that end at random points (finished, cancelled, abandoned, bad
// frames), for about NIDEVO_SOAK_SECONDS (default 60; scripts/soak.sh runs it longer). Every
// session is freed, and the server's resident memory stays flat after warm-up.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <random>
#include <thread>
#include <vector>

#include "metrics_scrape.hpp"
#include "server_process.hpp"
#include "service_fixtures.hpp"

namespace nidevo::test {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

double soakSeconds() {
  const char* env = std::getenv("NIDEVO_SOAK_SECONDS");
  return env ? std::max(12.0, std::atof(env)) : 60.0;
}

double metric(const ServerProcess& server, const std::string& series) {
  return client::valueOf(client::parsePrometheusText(client::httpGet(server.metricsUrl())), series);
}

// One client's life: sessions of 1-12 frames that end one of four ways.
void churn(const ServerProcess& server, const TestSequence& frames, unsigned seed,
           Clock::time_point until, std::atomic<int>* sessions) {
  std::mt19937 rng(seed);
  const auto encoding = client::parseFrameEncoding("raw");
  client::ChannelOptions options;
  options.target = server.target();
  options.connect_timeout_s = 10;
  client::Client client(options);
  double t = 0;
  v1::Frame frame;
  while (Clock::now() < until) {
    auto session = client.open(sessionFor(frames.camera, encoding), [](const auto&) {});
    const int n = std::uniform_int_distribution<int>(1, 12)(rng);
    const int ending = std::uniform_int_distribution<int>(0, 3)(rng);
    for (int i = 0; i < n; ++i) {
      client::encodeFrame(frames.frames[size_t(i) % frames.frames.size()],
                          frames.camera.depth_scale, encoding, &frame);
      frame.set_sequence(uint64_t(i));
      frame.set_timestamp(t += 0.033);
      if (ending == 3 && i == n / 2) frame.set_color("not an image");  // answered ERROR
      if (!session->send(frame)) break;
    }
    if (ending == 0 || ending == 3) session->finish();  // every answer, then OK
    if (ending == 1) session->cancel();                 // abort with frames in flight
    session.reset();                                    // ending 2: abandoned, cancelled here
    ++*sessions;
  }
}

// Rounds of 2 s in which 6 clients churn sessions; after each round, once every session is freed
// and the server has given the freed memory back (it does when no session is open), its resident
// memory is sampled: at that quiet point it holds no session, so what it keeps from round to round
// is what leaks. The idle timeout of 3 s makes the server look every 0.3 s.
TEST(Soak, SessionsEndingAtRandomAreAllFreedAndMemoryStaysFlat) {
  ServerProcess server({"--max_sessions=16", "--idle_timeout_s=3"});
  const TestSequence frames = renderOffice(4, 3);
  const double seconds = soakSeconds();
  const int rounds = std::max(6, int(seconds / 2));
  std::atomic<int> sessions{0};
  std::vector<size_t> rss, heap;  // after each round
  for (int round = 0; round < rounds; ++round) {
    const double releases = metric(server, "nidevo_memory_releases_total");
    const auto until = Clock::now() + 2s;
    std::vector<std::thread> clients;
    for (unsigned c = 0; c < 6; ++c)
      clients.emplace_back(
          [&, c] { churn(server, frames, 1000 * unsigned(round) + c, until, &sessions); });
    for (auto& c : clients) c.join();
    // Every session freed: the gauge returns to 0 within a few seconds of the last client.
    const auto freed_by = Clock::now() + 10s;
    while (metric(server, "nidevo_active_sessions") != 0 && Clock::now() < freed_by)
      std::this_thread::sleep_for(20ms);
    ASSERT_EQ(metric(server, "nidevo_active_sessions"), 0) << "round " << round;
    ASSERT_EQ(metric(server, "nidevo_queued_frames"), 0) << "round " << round;
    while (metric(server, "nidevo_memory_releases_total") == releases && Clock::now() < freed_by)
      std::this_thread::sleep_for(20ms);
    ASSERT_GT(metric(server, "nidevo_memory_releases_total"), releases) << "round " << round;
    rss.push_back(server.residentBytes());
    heap.push_back(size_t(metric(server, "nidevo_heap_allocated_bytes")));
  }
  EXPECT_GT(sessions.load(), 20 * rounds) << "too few sessions for a soak";

  // Flat: the median of the last third against the median of the second (the first third is
  // warm-up: gRPC's and the allocator's pools fill). The heap the allocator has handed out is
  // the leak check, within 2 %: a leak of one session's buffers (about 20 MB) every few rounds
  // fails it many times over, and so do 100 bytes kept per session. The resident size swings by up
  // to 10 % from one quiet point to the next with what the arenas keep. Since the server keeps
  // frame messages in the heap (fixed malloc thresholds, d216787), the medians of the thirds
  // moved by -6.9 to +12.4 % in 9 runs of 60 s on 2026-12-04, with the heap flat (+0.9-1.3 %)
  // and for servers before and after that day's changes alike; so the resident size is a gross
  // bound, 25 % (a leak of one session's buffers every few rounds still exceeds it), and its
  // flatness is shown by longer runs (soak.sh).
  const auto growth = [](const std::vector<size_t>& samples, const char* what) {
    const size_t third = samples.size() / 3;
    auto median = [](std::vector<size_t> v) {
      std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
      return v[v.size() / 2];
    };
    const size_t second =
        median({samples.begin() + long(third), samples.begin() + long(2 * third)});
    const size_t last = median({samples.begin() + long(2 * third), samples.end()});
    std::printf("soak: %s MB after each round:", what);
    for (size_t bytes : samples) std::printf(" %.1f", double(bytes) / 1e6);
    const double g = double(last) / double(second) - 1;
    std::printf(
        "\nsoak: %s median %.1f MB (second third) -> %.1f MB (last third), growth %.2f %%\n", what,
        double(second) / 1e6, double(last) / 1e6, 100 * g);
    return g;
  };
  std::printf("soak: %d sessions in %d rounds of 2 s\n", sessions.load(), rounds);
  EXPECT_LT(growth(heap, "heap allocated"), 0.02);
  EXPECT_LT(growth(rss, "resident"), 0.25);
}

}  // namespace
}  // namespace nidevo::test

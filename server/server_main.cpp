// nidevo-server: the NIDEVO odometry as a gRPC streaming service with Prometheus metrics.
#include <dlfcn.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <pthread.h>
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <future>
#include <iostream>
#include <memory>
#include <sstream>
#include <thread>

#include "absl/flags/flag.h"
#include "absl/synchronization/mutex.h"
#include "memory_release.hpp"
#include "nidevo/cli/cli.hpp"
#include "nidevo/cli/odometry_flags.hpp"
#include "nidevo/odometry/camera.hpp"
#include "nidevo/odometry/odometry.hpp"
#include "odometry_service.hpp"
#include "process_metrics.hpp"
#include "prometheus/exposer.h"
#include "server_config.hpp"
#include "server_metrics.hpp"
#include "token_auth.hpp"
#include "worker_pool.hpp"

namespace {
const nidevo::server::ServerConfig kDefaults;
}

NIDEVO_FLAG_HEADING("Server");
ABSL_FLAG(std::string, address, kDefaults.address,
          "gRPC listen address host:port (port 0: any free port, see --port_file)");
ABSL_FLAG(std::string, metrics_address, kDefaults.metrics_address,
          "Prometheus /metrics listen address host:port; empty: no metrics endpoint");
ABSL_FLAG(int, workers, kDefaults.workers,
          "Odometry worker threads shared by all sessions; 0: "
          "one per core");
ABSL_FLAG(int, max_sessions, kDefaults.max_sessions,
          "Concurrent sessions; the next stream fails with RESOURCE_EXHAUSTED");
ABSL_FLAG(int64_t, max_message_bytes, kDefaults.max_message_bytes,
          "Largest client message; larger fails the stream with RESOURCE_EXHAUSTED");
ABSL_FLAG(int, default_queue_capacity, kDefaults.default_queue_capacity,
          "Frames a session queues before its overload policy applies, unless it asks otherwise");
ABSL_FLAG(int, max_queue_capacity, kDefaults.max_queue_capacity,
          "Largest queue capacity a session may ask for");
ABSL_FLAG(double, idle_timeout_s, kDefaults.idle_timeout_s,
          "A session with no client message for this long ends with DEADLINE_EXCEEDED");
ABSL_FLAG(double, drain_timeout_s, kDefaults.drain_timeout_s,
          "On SIGTERM/SIGINT: open streams get this long to finish, then are cancelled");
ABSL_FLAG(bool, reflection, kDefaults.reflection, "Serve gRPC reflection");
ABSL_FLAG(double, keepalive_time_s, kDefaults.keepalive_time_s,
          "Server HTTP/2 keepalive ping interval");
ABSL_FLAG(double, keepalive_timeout_s, kDefaults.keepalive_timeout_s,
          "Close a connection whose keepalive ping is unanswered this long");
ABSL_FLAG(double, min_client_ping_interval_s, kDefaults.min_client_ping_interval_s,
          "Shortest client keepalive interval accepted (faster: GOAWAY too_many_pings)");
ABSL_FLAG(double, max_connection_age_s, kDefaults.max_connection_age_s,
          "Close connections after this age so clients rebalance; 0: never (a session lives on "
          "one connection, so keep it above the longest session plus the grace)");
ABSL_FLAG(double, max_connection_age_grace_s, kDefaults.max_connection_age_grace_s,
          "Time streams get to finish after max_connection_age; 0: unlimited");
ABSL_FLAG(int, http2_stream_window_bytes, kDefaults.http2_stream_window_bytes,
          "HTTP/2 receive window of each stream, bytes (0: gRPC's default, 64 KiB growing with "
          "its bandwidth-delay probe)");
ABSL_FLAG(int, http2_max_frame_bytes, kDefaults.http2_max_frame_bytes,
          "Largest HTTP/2 frame clients may send, bytes (0: gRPC's default, 16 KiB)");
ABSL_FLAG(std::string, tls_cert_file, "", "PEM certificate chain; with --tls_key_file enables TLS");
ABSL_FLAG(std::string, tls_key_file, "", "PEM private key of --tls_cert_file");
ABSL_FLAG(std::string, tls_client_ca_file, "",
          "Mutual TLS: PEM CA certificates; every client must present a certificate they sign "
          "(needs --tls_cert_file)");
ABSL_FLAG(std::string, token_file, "",
          "Bearer tokens, one per line ('#' comments): every call but health must carry "
          "'authorization: Bearer <token>' metadata. Re-read on SIGHUP; open sessions stay");
ABSL_FLAG(std::string, port_file, "",
          "Once serving, write 'grpc_port N' and 'metrics_port M' lines here (for scripts)");

namespace {

using nidevo::server::ServerConfig;

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

ServerConfig configFromFlags() {
  ServerConfig c;
  c.address = absl::GetFlag(FLAGS_address);
  c.metrics_address = absl::GetFlag(FLAGS_metrics_address);
  c.workers = absl::GetFlag(FLAGS_workers);
  if (c.workers == 0) c.workers = int(std::max(1u, std::thread::hardware_concurrency()));
  c.max_sessions = absl::GetFlag(FLAGS_max_sessions);
  c.max_message_bytes = absl::GetFlag(FLAGS_max_message_bytes);
  c.default_queue_capacity = absl::GetFlag(FLAGS_default_queue_capacity);
  c.max_queue_capacity = absl::GetFlag(FLAGS_max_queue_capacity);
  c.idle_timeout_s = absl::GetFlag(FLAGS_idle_timeout_s);
  c.drain_timeout_s = absl::GetFlag(FLAGS_drain_timeout_s);
  c.reflection = absl::GetFlag(FLAGS_reflection);
  c.keepalive_time_s = absl::GetFlag(FLAGS_keepalive_time_s);
  c.keepalive_timeout_s = absl::GetFlag(FLAGS_keepalive_timeout_s);
  c.min_client_ping_interval_s = absl::GetFlag(FLAGS_min_client_ping_interval_s);
  c.max_connection_age_s = absl::GetFlag(FLAGS_max_connection_age_s);
  c.max_connection_age_grace_s = absl::GetFlag(FLAGS_max_connection_age_grace_s);
  c.http2_stream_window_bytes = absl::GetFlag(FLAGS_http2_stream_window_bytes);
  c.http2_max_frame_bytes = absl::GetFlag(FLAGS_http2_max_frame_bytes);
  c.odometry = nidevo::cli::odometryConfigFromFlags();
  return c;
}

int ms(double seconds) { return int(std::min(seconds * 1000.0, 2.0e9)); }

std::shared_ptr<grpc::ServerCredentials> credentials() {
  const std::string cert = absl::GetFlag(FLAGS_tls_cert_file);
  const std::string key = absl::GetFlag(FLAGS_tls_key_file);
  if (cert.empty() != key.empty())
    throw std::invalid_argument("--tls_cert_file and --tls_key_file go together");
  const std::string client_ca = absl::GetFlag(FLAGS_tls_client_ca_file);
  if (!client_ca.empty() && cert.empty())
    throw std::invalid_argument("--tls_client_ca_file needs --tls_cert_file and --tls_key_file");
  if (cert.empty()) return grpc::InsecureServerCredentials();
  grpc::SslServerCredentialsOptions options(
      client_ca.empty() ? GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE
                        : GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY);
  if (!client_ca.empty()) options.pem_root_certs = readFile(client_ca);
  options.pem_key_cert_pairs.push_back({readFile(key), readFile(cert)});
  return grpc::SslServerCredentials(options);
}

void writePortFile(const std::string& path, int grpc_port, int metrics_port) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    out << "grpc_port " << grpc_port << "\nmetrics_port " << metrics_port << "\n";
    if (!out) throw std::runtime_error("cannot write " + tmp);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw std::runtime_error("cannot rename " + tmp + " to " + path);
}

// Plans FFTW for the projection size and touches every code path once, so the first session
// does not pay for it and health turns SERVING only when the server is really ready.
void warmUp(const nidevo::OdometryConfig& config) {
  const nidevo::Camera camera;  // the defaults: ICL-NUIM's VGA camera
  nidevo::Odometry odometry(camera, config);
  nidevo::RgbdFrame frame;
  frame.gray.resize(camera.width, camera.height, 128);
  frame.depth.resize(camera.width, camera.height, 2.0f);
  for (int i = 0; i < 2; ++i) {
    frame.timestamp = i;
    odometry.track(frame);
  }
}

// gRPC's reflection library registers its plugin for every server as soon as it is loaded, so it
// is loaded only when asked for; linking it would serve reflection whatever the flag says.
void enableReflection() {
  constexpr const char* kLibrary = "libgrpc++_reflection.so.1.51";
  if (!dlopen(kLibrary, RTLD_NOW | RTLD_GLOBAL))
    throw std::runtime_error(std::string("--reflection: cannot load ") + kLibrary + ": " +
                             dlerror());
}

// Serves /metrics on the configured address; returns the bound port, 0 when metrics are off,
// -1 (with a message) when the address cannot be bound.
int serveMetrics(const ServerConfig& config, nidevo::server::ServerMetrics& metrics,
                 std::unique_ptr<prometheus::Exposer>* exposer) {
  if (config.metrics_address.empty()) return 0;
  try {
    *exposer = std::make_unique<prometheus::Exposer>(config.metrics_address);
  } catch (const std::exception& e) {
    std::cerr << "nidevo-server: cannot serve metrics on " << config.metrics_address << ": "
              << e.what() << "\n";
    return -1;
  }
  (*exposer)->RegisterCollectable(metrics.registry());
  // The exposer keeps a weak pointer; the collector lives as long as the process.
  static const auto process = std::make_shared<nidevo::server::ProcessCollector>();
  (*exposer)->RegisterCollectable(process);
  static const auto heap = std::make_shared<nidevo::server::HeapCollector>();
  (*exposer)->RegisterCollectable(heap);
  return (*exposer)->GetListeningPorts().at(0);
}

// Listening port, message size, the HTTP/2 keepalive and connection-age policy and flow control.
void configureTransport(const ServerConfig& config, grpc::ServerBuilder* builder, int* grpc_port) {
  builder->AddListeningPort(config.address, credentials(), grpc_port);
  builder->SetMaxReceiveMessageSize(int(std::min<int64_t>(config.max_message_bytes, INT32_MAX)));
  builder->AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, ms(config.keepalive_time_s));
  builder->AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, ms(config.keepalive_timeout_s));
  builder->AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS,
                              ms(config.min_client_ping_interval_s));
  builder->AddChannelArgument(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  if (config.http2_stream_window_bytes > 0)
    builder->AddChannelArgument(GRPC_ARG_HTTP2_STREAM_LOOKAHEAD_BYTES,
                                config.http2_stream_window_bytes);
  if (config.http2_max_frame_bytes > 0)
    builder->AddChannelArgument(GRPC_ARG_HTTP2_MAX_FRAME_SIZE, config.http2_max_frame_bytes);
  if (config.max_connection_age_s > 0) {
    builder->AddChannelArgument(GRPC_ARG_MAX_CONNECTION_AGE_MS, ms(config.max_connection_age_s));
    if (config.max_connection_age_grace_s > 0)
      builder->AddChannelArgument(GRPC_ARG_MAX_CONNECTION_AGE_GRACE_MS,
                                  ms(config.max_connection_age_grace_s));
  }
}

sigset_t handledSignals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  return signals;
}

// Returns SIGTERM or SIGINT; a SIGHUP re-reads the token file on the way (never logs a token).
int waitForStopSignal(nidevo::server::TokenAuthenticator& auth) {
  const sigset_t signals = handledSignals();
  for (;;) {
    int signal_number = 0;
    sigwait(&signals, &signal_number);
    if (signal_number != SIGHUP) return signal_number;
    if (!auth.enabled()) {
      std::cerr << "nidevo-server: SIGHUP: no --token_file to reload" << std::endl;
    } else if (std::string error = auth.reload(); !error.empty()) {
      std::cerr << "nidevo-server: SIGHUP: " << error << "; keeping the " << auth.size()
                << " tokens loaded before" << std::endl;
    } else {
      std::cerr << "nidevo-server: SIGHUP: reloaded " << auth.size() << " tokens" << std::endl;
    }
  }
}

// Health and server info keep answering while open streams finish, so probes and load balancers
// see NOT_SERVING rather than a closed port; new streams get UNAVAILABLE. What is still open at
// the drain deadline is cancelled. Returns how many were.
int drain(const ServerConfig& config, nidevo::server::OdometryService& service,
          grpc::Server& server) {
  server.GetHealthCheckService()->Shutdown();
  service.beginDrain();
  const auto drain_end =
      std::chrono::steady_clock::now() + std::chrono::milliseconds(ms(config.drain_timeout_s));
  while (service.activeSessions() > 0 && std::chrono::steady_clock::now() < drain_end)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const int cancelled = service.activeSessions();
  server.Shutdown(std::chrono::system_clock::now());  // cancels what is still open
  server.Wait();
  return cancelled;
}

int run(const ServerConfig& config) {
  nidevo::server::ServerMetrics metrics(NIDEVO_VERSION);
  std::unique_ptr<prometheus::Exposer> exposer;  // after the registry (see build notes)
  const int metrics_port = serveMetrics(config, metrics, &exposer);
  if (metrics_port < 0) return 1;
  // On a thread of its own, whose stage-1 scratch (thread-local) goes when it ends: the main
  // thread never runs a stage again.
  std::async(std::launch::async, warmUp, config.odometry).get();

  auto pool = std::make_unique<nidevo::server::WorkerPool>(config.workers);
  const std::string token_file = absl::GetFlag(FLAGS_token_file);
  nidevo::server::TokenAuthenticator auth = token_file.empty()
                                                ? nidevo::server::TokenAuthenticator()
                                                : nidevo::server::TokenAuthenticator(token_file);
  auto service = std::make_unique<nidevo::server::OdometryService>(config, *pool, metrics, auth);
  grpc::EnableDefaultHealthCheckService(true);
  if (config.reflection) enableReflection();
  grpc::ServerBuilder builder;
  int grpc_port = 0;
  configureTransport(config, &builder, &grpc_port);
  builder.RegisterService(service.get());
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || grpc_port == 0) {
    std::cerr << "nidevo-server: cannot listen on " << config.address << "\n";
    return 1;
  }
  auto* health = server->GetHealthCheckService();
  health->SetServingStatus("", true);
  health->SetServingStatus("nidevo.v1.OdometryService", true);
  const std::string port_file = absl::GetFlag(FLAGS_port_file);
  if (!port_file.empty()) writePortFile(port_file, grpc_port, metrics_port);
  std::cerr << "nidevo-server " << NIDEVO_VERSION << ": serving nidevo.v1 on port " << grpc_port
            << (metrics_port ? ", metrics on port " + std::to_string(metrics_port) : "") << ", "
            << config.workers << " workers, at most " << config.max_sessions << " sessions"
            << (auth.enabled() ? ", " + std::to_string(auth.size()) + " bearer tokens" : "")
            << std::endl;

  const int signal_number = waitForStopSignal(auth);
  std::cerr << "nidevo-server: " << (signal_number == SIGTERM ? "SIGTERM" : "SIGINT")
            << ", draining " << service->activeSessions() << " sessions for up to "
            << config.drain_timeout_s << " s" << std::endl;
  const auto drain_start = std::chrono::steady_clock::now();
  const int cancelled = drain(config, *service, *server);
  if (cancelled > 0)
    std::cerr << "nidevo-server: drain deadline passed, cancelled " << cancelled << " sessions"
              << std::endl;
  pool.reset();  // finishes the stage tasks of cancelled sessions
  service.reset();
  std::cerr << "nidevo-server: stopped after "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - drain_start).count()
            << " s of draining" << std::endl;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // Every thread inherits this mask, so only sigwait in run() sees the signals.
  const sigset_t signals = handledSignals();
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  // Debian's Abseil has deadlock detection on; gRPC's own mutexes pay for it on every lock.
  absl::SetMutexDeadlockDetectionMode(absl::OnDeadlockCycle::kIgnore);
  nidevo::server::keepFrameBuffersMapped();

  const auto args = nidevo::cli::init(
      argc, argv,
      "nidevo-server [flags]\n\nServes the NIDEVO RGB-D odometry over gRPC (nidevo.v1, one "
      "stream per session) with Prometheus metrics.\nEvery flag can also be set as an "
      "environment variable NIDEVO_<FLAG> (e.g. NIDEVO_MAX_SESSIONS=8); flags win.");
  if (!args.empty()) return nidevo::cli::usageError("unexpected argument " + args[0]);
  try {
    const ServerConfig config = configFromFlags();
    if (std::string e = config.validate(); !e.empty()) return nidevo::cli::usageError(e);
    return run(config);
  } catch (const std::exception& e) {
    std::cerr << "nidevo-server: " << e.what() << "\n";
    return 1;
  }
}

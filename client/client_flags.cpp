#include "client_flags.hpp"

#include "absl/flags/flag.h"
#include "nidevo/cli/cli.hpp"

namespace {
const nidevo::client::ChannelOptions kDefaults;
}

NIDEVO_FLAG_HEADING("Connection and session (every command)");
ABSL_FLAG(std::string, target, kDefaults.target, "Server address host:port (any gRPC target)");
ABSL_FLAG(bool, tls, kDefaults.tls, "Connect with TLS");
ABSL_FLAG(std::string, ca_file, "", "PEM CA certificates for --tls (default: the system's)");
ABSL_FLAG(std::string, tls_cert_file, "",
          "Mutual TLS: this client's PEM certificate chain (with --tls and --tls_key_file)");
ABSL_FLAG(std::string, tls_key_file, "", "Mutual TLS: the private key of --tls_cert_file");
ABSL_FLAG(std::string, token_file, "",
          "File whose first line is the bearer token sent on every call (the server's "
          "--token_file); also NIDEVO_TOKEN_FILE");
ABSL_FLAG(double, connect_timeout_s, kDefaults.connect_timeout_s,
          "Give up connecting (and on unary calls) after this long");
ABSL_FLAG(double, keepalive_time_s, kDefaults.keepalive_time_s,
          "HTTP/2 keepalive ping interval (the server accepts 10 s or more by default)");
ABSL_FLAG(int, http2_stream_window_bytes, kDefaults.http2_stream_window_bytes,
          "HTTP/2 receive window of each stream, bytes (0: gRPC's default); the frames sent obey "
          "the server's --http2_stream_window_bytes");
ABSL_FLAG(int, http2_max_frame_bytes, kDefaults.http2_max_frame_bytes,
          "Largest HTTP/2 frame the server may send, bytes (0: gRPC's default, 16 KiB)");
ABSL_FLAG(std::string, load_balancing, "",
          "gRPC load-balancing policy, e.g. round_robin with a dns:/// target");

ABSL_FLAG(std::string, encoding, "png",
          "Frame encoding on the wire: raw (GRAY8 + UINT16), raw-f32, png, jpeg");
ABSL_FLAG(std::string, policy, "block",
          "Overload policy: block (lose nothing) or latest (drop old frames, real time)");
ABSL_FLAG(int, queue_capacity, 0, "Session queue capacity (0: the server's default)");
ABSL_FLAG(double, deadline_s, 0,
          "Deadline of each whole stream, seconds (0: none); past it the stream ends "
          "DEADLINE_EXCEEDED");

namespace nidevo::client {

FrameEncoding frameEncodingFromFlags() { return parseFrameEncoding(encodingName()); }

std::string encodingName() { return absl::GetFlag(FLAGS_encoding); }

SessionOptions sessionOptionsFromFlags(const Camera& camera) {
  const FrameEncoding encoding = frameEncodingFromFlags();
  SessionOptions options;
  options.camera = camera;
  options.color_encoding = encoding.color;
  options.depth_encoding = encoding.depth;
  const std::string policy = absl::GetFlag(FLAGS_policy);
  if (policy != "block" && policy != "latest")
    throw std::invalid_argument("--policy: '" + policy + "' is not block or latest");
  options.overload_policy =
      policy == "latest" ? v1::OVERLOAD_POLICY_LATEST : v1::OVERLOAD_POLICY_BLOCK;
  const int capacity = absl::GetFlag(FLAGS_queue_capacity);
  if (capacity < 0) throw std::invalid_argument("--queue_capacity: must not be negative");
  options.queue_capacity = uint32_t(capacity);
  options.deadline_s = absl::GetFlag(FLAGS_deadline_s);
  if (!(options.deadline_s >= 0)) throw std::invalid_argument("--deadline_s: must not be negative");
  return options;
}

ChannelOptions channelOptionsFromFlags() {
  ChannelOptions o;
  o.target = absl::GetFlag(FLAGS_target);
  o.tls = absl::GetFlag(FLAGS_tls);
  o.ca_file = absl::GetFlag(FLAGS_ca_file);
  o.cert_file = absl::GetFlag(FLAGS_tls_cert_file);
  o.key_file = absl::GetFlag(FLAGS_tls_key_file);
  if ((!o.cert_file.empty() || !o.key_file.empty()) && !o.tls)
    throw std::invalid_argument("--tls_cert_file and --tls_key_file need --tls");
  if (const std::string path = absl::GetFlag(FLAGS_token_file); !path.empty())
    o.bearer_token = readBearerToken(path);
  o.connect_timeout_s = absl::GetFlag(FLAGS_connect_timeout_s);
  o.keepalive_time_s = absl::GetFlag(FLAGS_keepalive_time_s);
  o.http2_stream_window_bytes = absl::GetFlag(FLAGS_http2_stream_window_bytes);
  o.http2_max_frame_bytes = absl::GetFlag(FLAGS_http2_max_frame_bytes);
  if (o.http2_stream_window_bytes < 0 || o.http2_max_frame_bytes < 0)
    throw std::invalid_argument(
        "--http2_stream_window_bytes and --http2_max_frame_bytes: not negative");
  o.load_balancing = absl::GetFlag(FLAGS_load_balancing);
  return o;
}

}  // namespace nidevo::client

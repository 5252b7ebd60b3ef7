#include "server_config.hpp"

namespace nidevo::server {

std::string ServerConfig::validate() const {
  if (address.empty()) return "address: empty";
  if (workers < 1 || workers > 256) return "workers: must be 1..256";
  if (max_sessions < 1) return "max_sessions: must be at least 1";
  if (max_message_bytes < 1024) return "max_message_bytes: must be at least 1024";
  if (default_queue_capacity < 1) return "default_queue_capacity: must be at least 1";
  if (max_queue_capacity < default_queue_capacity)
    return "max_queue_capacity: must be at least default_queue_capacity";
  if (!(idle_timeout_s > 0)) return "idle_timeout_s: must be positive";
  if (!(drain_timeout_s >= 0)) return "drain_timeout_s: must not be negative";
  if (!(keepalive_time_s > 0)) return "keepalive_time_s: must be positive";
  if (!(keepalive_timeout_s > 0)) return "keepalive_timeout_s: must be positive";
  if (!(min_client_ping_interval_s >= 0)) return "min_client_ping_interval_s: must not be negative";
  if (!(max_connection_age_s >= 0)) return "max_connection_age_s: must not be negative";
  if (!(max_connection_age_grace_s >= 0)) return "max_connection_age_grace_s: must not be negative";
  if (http2_stream_window_bytes != 0 &&
      (http2_stream_window_bytes < 65535 || http2_stream_window_bytes > (1 << 30)))
    return "http2_stream_window_bytes: must be 0 (gRPC's default) or 65535..1073741824";
  if (http2_max_frame_bytes != 0 &&
      (http2_max_frame_bytes < 16384 || http2_max_frame_bytes > 16777215))
    return "http2_max_frame_bytes: must be 0 (gRPC's default) or 16384..16777215";
  if (std::string e = odometry.validate(); !e.empty()) return e;
  return {};
}

}  // namespace nidevo::server

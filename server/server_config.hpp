#pragma once
// Every setting of the server in one struct with defaults; main fills it from flags.
#include <cstdint>
#include <string>

#include "nidevo/odometry/odometry_config.hpp"

namespace nidevo::server {

struct ServerConfig {
  std::string address = "0.0.0.0:50051";
  std::string metrics_address = "0.0.0.0:9464";  // empty: no metrics endpoint
  int workers = 0;                               // 0: one per core
  int max_sessions = 32;
  int64_t max_message_bytes = 16 << 20;  // a raw 640x480 RGB8 + UINT16 frame is ~1.5 MB
  int default_queue_capacity = 4;
  int max_queue_capacity = 64;
  double idle_timeout_s = 30;
  double drain_timeout_s = 10;
  bool reflection = false;
  // HTTP/2 keepalive; the client library uses the same defaults.
  double keepalive_time_s = 60;
  double keepalive_timeout_s = 20;
  double min_client_ping_interval_s = 10;  // pings more frequent than this: GOAWAY too_many_pings
  double max_connection_age_s = 0;         // 0: unlimited (sessions are long-lived streams)
  double max_connection_age_grace_s = 0;
  // HTTP/2 flow control of the frames coming in. A stream's receive window (gRPC's "lookahead";
  // 0: gRPC's default, 64 KiB growing with its BDP probe) and the largest HTTP/2 frame a
  // client may send (0: gRPC's default, 16 KiB). A raw VGA frame is 0.9 MB.
  int http2_stream_window_bytes = 0;
  int http2_max_frame_bytes = 0;
  OdometryConfig odometry;

  // Empty when valid, else a message naming the bad setting.
  [[nodiscard]] std::string validate() const;
};

}  // namespace nidevo::server

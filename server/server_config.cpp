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
  if (std::string e = odometry.validate(); !e.empty()) return e;
  return {};
}

}  // namespace nidevo::server

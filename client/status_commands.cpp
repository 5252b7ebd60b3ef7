// health and info: one unary call each.
#include <cstdio>
#include <iostream>

#include "absl/flags/flag.h"
#include "client_flags.hpp"
#include "commands.hpp"
#include "nidevo/cli/cli.hpp"

NIDEVO_FLAG_HEADING("info and health");
ABSL_FLAG(std::string, service, "nidevo.v1.OdometryService",
          "health: service name to check (empty: the whole server)");

namespace nidevo::client {

int healthCommand() {
  Client client(channelOptionsFromFlags());
  bool serving = false;
  const grpc::Status status = client.health(absl::GetFlag(FLAGS_service), &serving);
  if (!status.ok()) {
    std::printf("%s: %s\n", statusCodeName(status.error_code()).c_str(),
                status.error_message().c_str());
    return 1;
  }
  std::printf("%s\n", serving ? "SERVING" : "NOT_SERVING");
  return serving ? 0 : 1;
}

int infoCommand() {
  Client client(channelOptionsFromFlags());
  v1::ServerInfo info;
  const grpc::Status status = client.serverInfo(&info);
  if (!status.ok()) {
    std::printf("%s: %s\n", statusCodeName(status.error_code()).c_str(),
                status.error_message().c_str());
    return 1;
  }
  std::printf("version            %s (%s)\n", info.version().c_str(), info.api().c_str());
  std::printf("sessions           %u active, at most %u\n", info.active_sessions(),
              info.max_sessions());
  std::printf("worker threads     %u\n", info.worker_threads());
  std::printf("max message        %llu bytes\n", (unsigned long long)info.max_message_bytes());
  std::printf("queue capacity     %u by default, at most %u\n", info.default_queue_capacity(),
              info.max_queue_capacity());
  std::printf("idle timeout       %g s\n", info.idle_timeout_seconds());
  std::printf("colour encodings  ");
  for (int e : info.color_encodings())
    std::printf(" %s", v1::ColorEncoding_Name(v1::ColorEncoding(e)).c_str() + 15);
  std::printf("\ndepth encodings   ");
  for (int e : info.depth_encodings())
    std::printf(" %s", v1::DepthEncoding_Name(v1::DepthEncoding(e)).c_str() + 15);
  std::printf("\n");
  return 0;
}

}  // namespace nidevo::client

// nidevo-client: replay a sequence through a server, load-test it, check health, show its info.
#include <iostream>
#include <string>

#include "commands.hpp"
#include "nidevo/cli/cli.hpp"

int main(int argc, char** argv) {
  const auto args = nidevo::cli::init(
      argc, argv,
      "nidevo-client <command> [flags]\n\nCommands:\n"
      "  replay  stream a dataset folder or synthetic scene to the server, write the trajectory,\n"
      "          print the ATE where ground truth exists\n"
      "  load    N concurrent sessions at a rate for a duration (--sessions 1,2,4 sweeps);\n"
      "          latency percentiles from send to pose, throughput, drops, errors\n"
      "  health  grpc.health.v1 check; exit 0 only when SERVING (container health check)\n"
      "  info    the server's version, limits and encodings\n\n"
      "Every flag can also be set as NIDEVO_<FLAG> in the environment (e.g. "
      "NIDEVO_TARGET=host:50051).");
  if (args.size() != 1)
    return nidevo::cli::usageError(
        "nidevo-client: give exactly one command: replay, load, "
        "health or info");
  const std::string& command = args[0];
  try {
    if (command == "replay") return nidevo::client::replayCommand();
    if (command == "load") return nidevo::client::loadCommand();
    if (command == "health") return nidevo::client::healthCommand();
    if (command == "info") return nidevo::client::infoCommand();
  } catch (const std::exception& e) {
    std::cerr << "nidevo-client " << command << ": " << e.what() << "\n";
    return 1;
  }
  return nidevo::cli::usageError("nidevo-client: unknown command '" + command +
                                 "' (replay, load, health, info)");
}

#pragma once
// Runs the real nidevo-server binary on free loopback ports for a test.
#include <sys/types.h>

#include <string>
#include <vector>

namespace nidevo::test {

class ServerProcess {
 public:
  // Starts the server with --address/--metrics_address on 127.0.0.1:0 plus `extra_flags`, and
  // waits until it has written its port file. `environment` entries are NAME=value.
  // Throws std::runtime_error on failure.
  explicit ServerProcess(const std::vector<std::string>& extra_flags = {},
                         const std::vector<std::string>& environment = {});
  ~ServerProcess();  // SIGKILL if still running

  std::string target() const { return "127.0.0.1:" + std::to_string(grpc_port_); }
  std::string metricsUrl() const {
    return "http://127.0.0.1:" + std::to_string(metrics_port_) + "/metrics";
  }
  int metricsPort() const { return metrics_port_; }
  // What the server wrote to stderr so far.
  std::string log() const;
  // Resident memory of the running server, bytes (VmRSS); 0 when not running.
  size_t residentBytes() const;
  void signal(int signal_number) const;
  // Exit status, or -1 if still running after timeout_s (or killed by a signal).
  int waitExit(double timeout_s);
  bool running();

 private:
  pid_t pid_ = -1;  // negated once reaped
  int exit_status_ = -1;
  int grpc_port_ = 0;
  int metrics_port_ = 0;
  std::string dir_;
};

// A TCP port that was free a moment ago (for programs that cannot take port 0).
int freeTcpPort();

// Runs a shell command; returns its exit status, stdout+stderr in *output.
int runCommand(const std::string& command, std::string* output);

std::string makeTempDir();

}  // namespace nidevo::test

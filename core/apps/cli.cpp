#include "cli.hpp"

#include <iostream>

#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/flags/usage_config.h"
#include "absl/strings/match.h"

namespace nidevo::cli {

std::vector<std::string> init(int argc, char** argv, const std::string& usage) {
  absl::SetProgramUsageMessage(usage);
  absl::FlagsUsageConfig config;
  // absl's --help lists only flags from a file named like the binary; ours live in *_main.cpp
  // and in the project's libraries, so list every flag that is not absl's own.
  config.contains_help_flags = [](absl::string_view file) {
    return !absl::StrContains(file, "absl/");
  };
  config.contains_helpshort_flags = config.contains_help_flags;
  config.normalize_filename = [](absl::string_view f) { return std::string(f); };
  absl::SetFlagsUsageConfig(config);
  std::vector<char*> rest = absl::ParseCommandLine(argc, argv);
  return std::vector<std::string>(rest.begin() + 1, rest.end());
}

int usageError(const std::string& message) {
  std::cerr << message << "\nTry --help.\n";
  return 2;
}

}  // namespace nidevo::cli

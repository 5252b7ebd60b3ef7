#include "cli.hpp"

#include <cctype>
#include <iostream>

#include "absl/flags/parse.h"
#include "absl/flags/reflection.h"
#include "absl/flags/usage.h"
#include "absl/flags/usage_config.h"
#include "absl/strings/match.h"

extern char** environ;

namespace nidevo::cli {

namespace {

// NIDEVO_MAX_SESSIONS=8 means --max_sessions=8 for a program that has that flag. These go
// before the real arguments, so the command line wins.
std::vector<std::string> flagsFromEnvironment() {
  std::vector<std::string> args;
  constexpr absl::string_view kPrefix = "NIDEVO_";
  for (char** e = environ; e && *e; ++e) {
    absl::string_view entry(*e);
    const size_t eq = entry.find('=');
    if (!absl::StartsWith(entry, kPrefix) || eq == absl::string_view::npos) continue;
    std::string name(entry.substr(kPrefix.size(), eq - kPrefix.size()));
    for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (absl::FindCommandLineFlag(name) == nullptr) continue;
    args.push_back("--" + name + "=" + std::string(entry.substr(eq + 1)));
  }
  return args;
}

}  // namespace

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
  std::vector<std::string> env_args = flagsFromEnvironment();
  std::vector<char*> args(argv, argv + argc);
  args.insert(args.begin() + 1, env_args.size(), nullptr);
  for (size_t i = 0; i < env_args.size(); ++i) args[1 + i] = env_args[i].data();
  std::vector<char*> rest = absl::ParseCommandLine(int(args.size()), args.data());
  return std::vector<std::string>(rest.begin() + 1, rest.end());
}

int usageError(const std::string& message) {
  std::cerr << message << "\nTry --help.\n";
  return 2;
}

}  // namespace nidevo::cli

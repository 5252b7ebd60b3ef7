#include "nidevo/cli/cli.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <iostream>
#include <map>

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

std::map<std::string, std::string>& headingByFile() {
  static auto* headings = new std::map<std::string, std::string>();  // never destroyed: used
  return *headings;                                                  // during static init
}

constexpr const char* kDefaultHeading = "Options";

bool wantsHelp(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const absl::string_view a(argv[i]);
    if (a == "--") return false;
    if (a == "--help" || a == "-help" || a == "-h" || a == "--helpfull") return true;
  }
  return false;
}

// Usage text, then each heading's flags sorted by name: "--name=default" and the help text.
// The program's own heading ("Options") comes first; absl's built-in flags are left out.
void printHelp(const std::string& program, const std::string& usage) {
  std::map<std::string, std::vector<const absl::CommandLineFlag*>> by_heading;
  for (const auto& [name, flag] : absl::GetAllFlags()) {
    const std::string file = flag->Filename();
    if (absl::StrContains(file, "absl/")) continue;
    const auto it = headingByFile().find(file);
    by_heading[it == headingByFile().end() ? kDefaultHeading : it->second].push_back(flag);
  }
  std::vector<std::string> headings;
  for (const auto& entry : by_heading) headings.push_back(entry.first);
  std::stable_partition(headings.begin(), headings.end(),
                        [](const std::string& h) { return h == kDefaultHeading; });
  std::cout << program << ": " << usage << "\n";
  for (const std::string& heading : headings) {
    auto& flags = by_heading[heading];
    std::sort(flags.begin(), flags.end(), [](auto* a, auto* b) { return a->Name() < b->Name(); });
    std::cout << "\n" << heading << ":\n";
    for (const auto* flag : flags) {
      const std::string value = flag->DefaultValue();
      std::cout << "  --" << flag->Name() << "=" << (value.empty() ? "\"\"" : value) << "\n      "
                << flag->Help() << "\n";
    }
  }
  if (!absl::StrContains(usage, "NIDEVO_"))
    std::cout << "\nEvery flag may also be set as an environment variable NIDEVO_<FLAG> "
                 "(upper case); the command line wins.\n";
}

}  // namespace

bool registerFlagHeading(const char* source_file, const char* heading) {
  headingByFile()[source_file] = heading;
  return true;
}

std::vector<std::string> init(int argc, char** argv, const std::string& usage) {
  absl::SetProgramUsageMessage(usage);
  absl::FlagsUsageConfig config;
  // Flag file names as compiled (__FILE__), which is how registerFlagHeading keys them; absl's
  // default strips leading slashes.
  config.normalize_filename = [](absl::string_view f) { return std::string(f); };
  absl::SetFlagsUsageConfig(config);
  if (wantsHelp(argc, argv)) {
    const std::string path(argc > 0 ? argv[0] : "nidevo");
    printHelp(path.substr(path.find_last_of('/') + 1), usage);
    std::exit(0);
  }
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

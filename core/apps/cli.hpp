#pragma once
// Shared start-up for the command-line tools: absl flags with a usage line and a --help that
// lists this program's own flags.
#include <string>
#include <vector>

namespace nidevo::cli {

// Parses flags, each also settable as an environment variable NIDEVO_<FLAG_NAME> (the command
// line wins); returns the positional arguments (argv[0] excluded).
std::vector<std::string> init(int argc, char** argv, const std::string& usage);
// Prints "program: message" to stderr and returns exit code 2 (bad usage) for main to return.
int usageError(const std::string& message);

}  // namespace nidevo::cli

#pragma once
// Shared start-up for the command-line tools: absl flags, each also settable from the
// environment, and a --help that lists this program's flags under readable headings.
#include <string>
#include <vector>

namespace nidevo::cli {

// Parses flags, each also settable as an environment variable NIDEVO_<FLAG_NAME> (the command
// line wins); returns the positional arguments (argv[0] excluded). --help (or -h) prints the
// usage text and every flag of the program, grouped by heading, and exits 0.
std::vector<std::string> init(int argc, char** argv, const std::string& usage);
// Prints "program: message" to stderr and returns exit code 2 (bad usage) for main to return.
int usageError(const std::string& message);

// Names the --help heading of the flags defined in `source_file` (pass __FILE__); flags of a
// file without one are listed under "Options". Returns true, for use as a static initialiser.
bool registerFlagHeading(const char* source_file, const char* heading);

}  // namespace nidevo::cli

// In a file that defines flags: NIDEVO_FLAG_HEADING("Synthetic scene");
#define NIDEVO_FLAG_HEADING(heading)                                   \
  [[maybe_unused]] static const bool nidevo_flag_heading_registered_ = \
      ::nidevo::cli::registerFlagHeading(__FILE__, heading)

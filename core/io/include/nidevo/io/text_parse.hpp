#pragma once
// Whitespace-separated text fields with '#' comments, as in the TUM list files.
#include <string>
#include <vector>

namespace nidevo {

// Fields of a line with any '#' comment removed; empty for blank or comment lines.
std::vector<std::string> splitFields(const std::string& line);
// Whole-field number parse; throws std::invalid_argument naming the text.
double parseDouble(const std::string& text);

}  // namespace nidevo

#include "nidevo/io/text_parse.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace nidevo {

std::vector<std::string> splitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::istringstream ss(line.substr(0, line.find('#')));
  std::string f;
  while (ss >> f) fields.push_back(f);
  return fields;
}

double parseDouble(const std::string& text) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (end == begin || *end != '\0' || !std::isfinite(v)) {
    throw std::invalid_argument("'" + text + "' is not a finite number");
  }
  return v;
}

}  // namespace nidevo

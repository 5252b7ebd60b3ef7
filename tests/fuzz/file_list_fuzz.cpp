// The TUM/ICL-NUIM list parsers (rgb.txt / depth.txt, associations.txt) and the timestamp
// association on arbitrary text: parsed entries or a std::runtime_error naming file and line.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "fuzz_check.hpp"
#include "nidevo/io/dataset.hpp"

namespace {

void associateWithItself(const std::vector<nidevo::TimedFile>& files) {
  std::vector<double> a, b;
  for (size_t i = 0; i < files.size(); ++i) (i % 2 ? b : a).push_back(files[i].timestamp);
  const auto pairs = nidevo::associateByTimestamp(a, b, 0.02);
  std::set<size_t> used_a, used_b;
  for (auto [i, j] : pairs) {
    NIDEVO_FUZZ_CHECK(i < a.size() && j < b.size());
    NIDEVO_FUZZ_CHECK(used_a.insert(i).second && used_b.insert(j).second);
    // The bound as the function applies it (b within [a - d, a + d] in floating point).
    NIDEVO_FUZZ_CHECK(b[j] >= a[i] - 0.02 && b[j] <= a[i] + 0.02);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    std::istringstream in(text);
    const auto files = nidevo::parseFileList(in, "fuzz");
    for (const auto& f : files) NIDEVO_FUZZ_CHECK(std::isfinite(f.timestamp) && !f.path.empty());
    associateWithItself(files);
  } catch (const std::runtime_error&) {
  }
  try {
    std::istringstream in(text);
    for (const auto& e : nidevo::parseAssociations(in, "fuzz"))
      NIDEVO_FUZZ_CHECK(std::isfinite(e.rgb.timestamp) && std::isfinite(e.depth.timestamp));
  } catch (const std::runtime_error&) {
  }
  return 0;
}

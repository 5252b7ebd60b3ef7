// The camera file parser on arbitrary text: a Camera that passes validation, or a
// std::runtime_error naming what was wrong; nothing else.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>

#include "fuzz_check.hpp"
#include "nidevo/io/camera_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const nidevo::Camera camera = nidevo::parseCameraText(in, "fuzz");
    NIDEVO_FUZZ_CHECK(camera.validate().empty());
  } catch (const std::runtime_error&) {
  }
  return 0;
}

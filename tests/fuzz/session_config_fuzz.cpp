// A stream's first message on arbitrary bytes: parsed as a SessionConfig and validated. A config
// that passes must give a decoder whose camera the odometry accepts; one that fails must say
// which field ("config.<field>: ...").
#include <cstddef>
#include <cstdint>
#include <string>

#include "frame_decoder.hpp"
#include "fuzz_check.hpp"
#include "google/protobuf/stubs/logging.h"
#include "nidevo/v1/odometry.pb.h"

// Protobuf logs every string field that is not UTF-8; the parse result says so already.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  google::protobuf::SetLogHandler(nullptr);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  nidevo::v1::SessionConfig config;
  if (!config.ParseFromArray(data, int(size))) return 0;
  const std::string error = nidevo::server::FrameDecoder::validate(config);
  if (!error.empty()) {
    NIDEVO_FUZZ_CHECK(error.rfind("config.", 0) == 0);
    return 0;
  }
  const nidevo::server::FrameDecoder decoder(config);
  NIDEVO_FUZZ_CHECK(decoder.camera().validate().empty());
  NIDEVO_FUZZ_CHECK(decoder.camera().width == int(config.camera().width()));
  NIDEVO_FUZZ_CHECK(decoder.camera().height == int(config.camera().height()));
  return 0;
}

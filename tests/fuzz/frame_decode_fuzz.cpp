// Frame decoding for every encoding. Input: 6 header bytes (colour encoding, depth encoding,
// width - 1, height - 1, depth scale as little-endian uint16), then a serialized v1::Frame.
// A frame either decodes to images of the session's size with depth finite and >= 0, or the
// error names the frame field ("frame.color: ..." / "frame.depth: ...").
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "frame_decoder.hpp"
#include "fuzz_check.hpp"
#include "nidevo/v1/odometry.pb.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  constexpr size_t kHeader = 6;
  if (size < kHeader) return 0;
  nidevo::v1::SessionConfig config;
  config.set_color_encoding(nidevo::v1::ColorEncoding(data[0] % 6));
  config.set_depth_encoding(nidevo::v1::DepthEncoding(data[1] % 4));
  auto* camera = config.mutable_camera();
  camera->set_width(1u + data[2] % 64u);
  camera->set_height(1u + data[3] % 64u);
  camera->set_fx(50);
  camera->set_fy(50);
  camera->set_cx(0.5 * camera->width());
  camera->set_cy(0.5 * camera->height());
  config.set_depth_scale(double(data[4] | (data[5] << 8)));
  if (!nidevo::server::FrameDecoder::validate(config).empty()) return 0;
  nidevo::v1::Frame frame;
  if (!frame.ParseFromArray(data + kHeader, int(size - kHeader))) return 0;

  const nidevo::server::FrameDecoder decoder(config);
  nidevo::RgbdFrame out;
  const std::string error = decoder.decode(frame, &out);
  if (!error.empty()) {
    NIDEVO_FUZZ_CHECK(error.rfind("frame.color: ", 0) == 0 || error.rfind("frame.depth: ", 0) == 0);
    return 0;
  }
  const int w = int(camera->width()), h = int(camera->height());
  NIDEVO_FUZZ_CHECK(out.gray.width == w && out.gray.height == h);
  NIDEVO_FUZZ_CHECK(out.depth.width == w && out.depth.height == h);
  NIDEVO_FUZZ_CHECK(out.gray.data.size() == size_t(w) * size_t(h));
  NIDEVO_FUZZ_CHECK(out.depth.data.size() == size_t(w) * size_t(h));
  for (float z : out.depth.data) NIDEVO_FUZZ_CHECK(std::isfinite(z) && z >= 0.f);
  return 0;
}

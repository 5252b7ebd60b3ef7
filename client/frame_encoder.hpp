#pragma once
// Encodes the core's RgbdFrame (grey + metric depth) for the wire in any nidevo.v1 encoding.
#include <string>

#include "nidevo/odometry/image.hpp"
#include "nidevo/v1/odometry.pb.h"

namespace nidevo::client {

struct FrameEncoding {
  v1::ColorEncoding color = v1::COLOR_ENCODING_GRAY8;
  v1::DepthEncoding depth = v1::DEPTH_ENCODING_UINT16;
  int jpeg_quality = 95;
};

// "raw" (GRAY8 + UINT16), "raw-f32" (GRAY8 + FLOAT32), "png" (PNG + PNG16),
// "jpeg" (JPEG + PNG16). Throws std::invalid_argument naming the choices.
FrameEncoding parseFrameEncoding(const std::string& name);

// Fills frame.color/depth (and timestamp); the caller sets the sequence number.
void encodeFrame(const RgbdFrame& image, double depth_scale, const FrameEncoding& encoding,
                 v1::Frame* frame);

}  // namespace nidevo::client

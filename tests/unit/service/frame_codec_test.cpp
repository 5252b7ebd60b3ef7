// Client encoding and server decoding of frames: round trips with known answers, and bad input
// named precisely.
#include <gtest/gtest.h>

#include <cmath>

#include "frame_decoder.hpp"
#include "frame_encoder.hpp"

namespace nidevo {
namespace {

RgbdFrame testFrame(int w, int h) {
  RgbdFrame f;
  f.timestamp = 12.5;
  f.gray.resize(w, h);
  f.depth.resize(w, h);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      f.gray.at(u, v) = uint8_t((u * 7 + v * 13) % 256);
      f.depth.at(u, v) = (u + v) % 17 == 0 ? 0.f : 0.5f + 0.001f * float(u) + 0.0137f * float(v);
    }
  return f;
}

v1::SessionConfig configFor(int w, int h, const client::FrameEncoding& e) {
  v1::SessionConfig c;
  c.mutable_camera()->set_fx(300);
  c.mutable_camera()->set_fy(-300);
  c.mutable_camera()->set_cx(w / 2.0);
  c.mutable_camera()->set_cy(h / 2.0);
  c.mutable_camera()->set_width(uint32_t(w));
  c.mutable_camera()->set_height(uint32_t(h));
  c.set_color_encoding(e.color);
  c.set_depth_encoding(e.depth);
  c.set_depth_scale(5000);
  return c;
}

TEST(FrameCodec, EveryEncodingRoundTrips) {
  const RgbdFrame in = testFrame(64, 48);
  for (const char* name : {"raw", "raw-f32", "png", "jpeg"}) {
    SCOPED_TRACE(name);
    const client::FrameEncoding e = client::parseFrameEncoding(name);
    const v1::SessionConfig config = configFor(64, 48, e);
    ASSERT_EQ(server::FrameDecoder::validate(config), "");
    server::FrameDecoder decoder(config);
    v1::Frame wire;
    client::encodeFrame(in, 5000, e, &wire);
    RgbdFrame out;
    ASSERT_EQ(decoder.decode(wire, &out), "");
    EXPECT_EQ(out.timestamp, 12.5);
    double max_gray_error = 0, max_depth_error = 0;
    for (size_t i = 0; i < in.gray.size(); ++i) {
      max_gray_error =
          std::max(max_gray_error, std::abs(double(in.gray.data[i]) - out.gray.data[i]));
      max_depth_error =
          std::max(max_depth_error, std::abs(double(in.depth.data[i]) - out.depth.data[i]));
      if (in.depth.data[i] == 0.f) {
        EXPECT_EQ(out.depth.data[i], 0.f);
      }
    }
    // JPEG is lossy on this busy pattern; everything else is exact up to the 1/5000 m step.
    EXPECT_LE(max_gray_error, std::string(name) == "jpeg" ? 40.0 : 0.0);
    EXPECT_LE(max_depth_error, std::string(name) == "raw-f32" ? 0.0 : 0.5 / 5000 + 1e-7);
  }
}

TEST(FrameCodec, ColourIsConvertedToGreyLikeTheDatasetLoader) {
  client::FrameEncoding e;
  e.color = v1::COLOR_ENCODING_RGB8;
  const v1::SessionConfig config = configFor(2, 1, e);
  server::FrameDecoder decoder(config);
  v1::Frame wire;
  wire.set_color(std::string("\xff\x00\x00\x00\x00\xff", 6));  // red, blue
  wire.set_depth(std::string(4, '\0'));
  RgbdFrame out;
  ASSERT_EQ(decoder.decode(wire, &out), "");
  EXPECT_EQ(out.gray.at(0, 0), 76);  // 0.299 * 255
  EXPECT_EQ(out.gray.at(1, 0), 29);  // 0.114 * 255
}

TEST(FrameCodec, BadFramesAreNamed) {
  const client::FrameEncoding raw = client::parseFrameEncoding("raw");
  server::FrameDecoder decoder(configFor(8, 8, raw));
  RgbdFrame out;
  v1::Frame wire;
  client::encodeFrame(testFrame(8, 8), 5000, raw, &wire);
  v1::Frame short_colour = wire;
  short_colour.mutable_color()->resize(63);
  EXPECT_NE(decoder.decode(short_colour, &out).find("frame.color: 63 bytes, expected 64"),
            std::string::npos);
  v1::Frame long_depth = wire;
  long_depth.mutable_depth()->append("xx");
  EXPECT_NE(decoder.decode(long_depth, &out).find("frame.depth: 130 bytes"), std::string::npos);

  const client::FrameEncoding png = client::parseFrameEncoding("png");
  server::FrameDecoder png_decoder(configFor(8, 8, png));
  client::encodeFrame(testFrame(8, 8), 5000, png, &wire);
  v1::Frame junk = wire;
  junk.set_color("\x89PNG garbage");
  EXPECT_NE(png_decoder.decode(junk, &out).find("frame.color: not a decodable image"),
            std::string::npos);
  v1::Frame grey_as_depth = wire;
  grey_as_depth.set_depth(wire.color());  // an 8-bit PNG where 16-bit depth belongs
  EXPECT_NE(png_decoder.decode(grey_as_depth, &out).find("16-bit"), std::string::npos);
  v1::Frame wrong_size;
  client::encodeFrame(testFrame(9, 8), 5000, png, &wrong_size);
  EXPECT_NE(png_decoder.decode(wrong_size, &out).find("9x8 but the camera is 8x8"),
            std::string::npos);
  v1::Frame empty = wire;
  empty.clear_depth();
  EXPECT_NE(png_decoder.decode(empty, &out).find("frame.depth: empty"), std::string::npos);
}

TEST(FrameCodec, FloatDepthNaNAndNegativeMeanNoMeasurement) {
  const client::FrameEncoding f32 = client::parseFrameEncoding("raw-f32");
  server::FrameDecoder decoder(configFor(2, 2, f32));
  const float values[4] = {1.5f, std::nanf(""), -2.f, INFINITY};
  v1::Frame wire;
  wire.set_color(std::string(4, 'a'));
  wire.set_depth(reinterpret_cast<const char*>(values), sizeof(values));
  RgbdFrame out;
  ASSERT_EQ(decoder.decode(wire, &out), "");
  EXPECT_EQ(out.depth.data[0], 1.5f);
  EXPECT_EQ(out.depth.data[1], 0.f);
  EXPECT_EQ(out.depth.data[2], 0.f);
  EXPECT_EQ(out.depth.data[3], 0.f);
}

TEST(FrameCodec, SessionConfigValidationNamesTheField) {
  const client::FrameEncoding raw = client::parseFrameEncoding("raw");
  auto check = [&](auto mutate, const std::string& field) {
    v1::SessionConfig c = configFor(64, 48, raw);
    mutate(&c);
    const std::string e = server::FrameDecoder::validate(c);
    EXPECT_EQ(e.rfind(field, 0), 0u) << "got: " << e;
  };
  check([](v1::SessionConfig* c) { c->clear_camera(); }, "config.camera");
  check([](v1::SessionConfig* c) { c->mutable_camera()->set_height(100000); },
        "config.camera.width/height");
  check([](v1::SessionConfig* c) { c->mutable_camera()->set_fy(0); }, "config.camera: fy");
  check([](v1::SessionConfig* c) { c->mutable_camera()->set_cx(1e9); }, "config.camera: cx");
  check([](v1::SessionConfig* c) { c->set_color_encoding(v1::ColorEncoding(9)); },
        "config.color_encoding");
  check([](v1::SessionConfig* c) { c->set_depth_encoding(v1::DEPTH_ENCODING_UNSPECIFIED); },
        "config.depth_encoding");
  check([](v1::SessionConfig* c) { c->set_depth_scale(-1); }, "config.depth_scale");
  check([](v1::SessionConfig* c) { c->set_overload_policy(v1::OverloadPolicy(7)); },
        "config.overload_policy");
  v1::SessionConfig f32 = configFor(64, 48, client::parseFrameEncoding("raw-f32"));
  f32.set_depth_scale(0);  // not needed for metric depth
  EXPECT_EQ(server::FrameDecoder::validate(f32), "");
}

TEST(FrameCodec, TheLensDistortionReachesTheSessionCamera) {
  v1::SessionConfig config =
      configFor(64, 48, {v1::COLOR_ENCODING_GRAY8, v1::DEPTH_ENCODING_FLOAT32});
  EXPECT_TRUE(server::FrameDecoder(config).camera().distortion.none());
  auto* lens = config.mutable_camera()->mutable_distortion();
  lens->set_k1(0.2624);
  lens->set_k2(-0.9531);
  lens->set_p1(-0.0054);
  lens->set_p2(0.0026);
  lens->set_k3(1.1633);
  ASSERT_EQ(server::FrameDecoder::validate(config), "");
  const Distortion d = server::FrameDecoder(config).camera().distortion;
  EXPECT_EQ(d.k1, 0.2624);
  EXPECT_EQ(d.k2, -0.9531);
  EXPECT_EQ(d.p1, -0.0054);
  EXPECT_EQ(d.p2, 0.0026);
  EXPECT_EQ(d.k3, 1.1633);
}

}  // namespace
}  // namespace nidevo

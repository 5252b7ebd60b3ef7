#include "nidevo/sim/texture.hpp"

#include <cmath>
#include <stdexcept>

namespace nidevo::synth {

TextureRichness parseTextureRichness(const std::string& name) {
  if (name == "rich") return TextureRichness::kRich;
  if (name == "low") return TextureRichness::kLow;
  if (name == "none") return TextureRichness::kNone;
  throw std::invalid_argument("unknown texture '" + name + "' (rich, low, none)");
}

const char* toString(TextureRichness t) {
  switch (t) {
    case TextureRichness::kRich:
      return "rich";
    case TextureRichness::kLow:
      return "low";
    case TextureRichness::kNone:
      return "none";
  }
  return "?";
}

namespace {

double latticeValue(uint32_t seed, int32_t i, int32_t j) {
  uint32_t h = seed * 0x9E3779B1u ^ uint32_t(i) * 0x85EBCA77u ^ uint32_t(j) * 0xC2B2AE3Du;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  h *= 0x297A2D39u;
  h ^= h >> 15;
  return double(h & 0xFFFFFF) / double(0xFFFFFF);  // [0, 1]
}

// Smooth value noise in [0, 1] with unit lattice spacing.
double valueNoise(uint32_t seed, double x, double y) {
  const double fx = std::floor(x), fy = std::floor(y);
  const int32_t i = int32_t(fx), j = int32_t(fy);
  double a = x - fx, b = y - fy;
  a = a * a * (3 - 2 * a);
  b = b * b * (3 - 2 * b);
  const double v00 = latticeValue(seed, i, j), v10 = latticeValue(seed, i + 1, j);
  const double v01 = latticeValue(seed, i, j + 1), v11 = latticeValue(seed, i + 1, j + 1);
  return (v00 * (1 - a) + v10 * a) * (1 - b) + (v01 * (1 - a) + v11 * a) * b;
}

}  // namespace

double textureValue(TextureRichness richness, uint32_t seed, double s, double t) {
  switch (richness) {
    case TextureRichness::kNone:
      return 1.0;
    case TextureRichness::kLow:
      // Near-uniform paint: a faint, very low-frequency shading variation.
      return 0.97 + 0.06 * valueNoise(seed, s * 0.8, t * 0.8);
    case TextureRichness::kRich: {
      double fbm = 0.0, amp = 0.5, freq = 3.0;
      for (int octave = 0; octave < 4; ++octave) {
        fbm += amp * valueNoise(seed + uint32_t(octave) * 101u, s * freq, t * freq);
        amp *= 0.5;
        freq *= 2.3;
      }
      // Sharp-edged blotches (posters, stains, wood grain) on top of the smooth noise.
      const double blotch = valueNoise(seed + 977u, s * 2.1, t * 2.1) > 0.62 ? 0.35 : 0.0;
      return 0.45 + 0.9 * fbm - blotch;
    }
  }
  return 1.0;
}

const char* toString(SurfacePattern p) {
  switch (p) {
    case SurfacePattern::kSequence:
      return "sequence";
    case SurfacePattern::kRich:
      return "rich";
    case SurfacePattern::kLow:
      return "low";
    case SurfacePattern::kNone:
      return "none";
    case SurfacePattern::kTiles:
      return "tiles";
    case SurfacePattern::kStripes:
      return "stripes";
    case SurfacePattern::kGrid:
      return "grid";
  }
  return "?";
}

namespace {

// Position within the period, in [0, 1).
double phaseOf(double x, double period) {
  const double p = x / period;
  return p - std::floor(p);
}

}  // namespace

double patternValue(SurfacePattern pattern, TextureRichness sequence_texture, uint32_t seed,
                    double period, double s, double t) {
  switch (pattern) {
    case SurfacePattern::kSequence:
      return textureValue(sequence_texture, seed, s, t);
    case SurfacePattern::kRich:
      return textureValue(TextureRichness::kRich, seed, s, t);
    case SurfacePattern::kLow:
      return textureValue(TextureRichness::kLow, seed, s, t);
    case SurfacePattern::kNone:
      return 1.0;
    case SurfacePattern::kTiles: {
      // Light and dark tiles of half the period in a checkerboard (so the pattern repeats every
      // period), with a dark grout line 4 % of a tile wide.
      const double tile = period / 2;
      if (phaseOf(s, tile) < 0.04 || phaseOf(t, tile) < 0.04) return 0.35;
      const int64_t parity = int64_t(std::floor(s / tile)) + int64_t(std::floor(t / tile));
      return parity % 2 ? 0.8 : 1.15;
    }
    case SurfacePattern::kStripes:
      return phaseOf(s, period) < 0.5 ? 0.65 : 1.2;
    case SurfacePattern::kGrid:
      return phaseOf(s, period) < 0.08 || phaseOf(t, period) < 0.08 ? 0.4 : 1.05;
  }
  return 1.0;
}

}  // namespace nidevo::synth

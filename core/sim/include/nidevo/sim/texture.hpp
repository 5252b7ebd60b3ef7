#pragma once
#include <cstdint>
#include <string>

namespace nidevo::synth {

enum class TextureRichness { kRich, kLow, kNone };

TextureRichness parseTextureRichness(const std::string& name);  // rich, low, none
const char* toString(TextureRichness t);

// Reflectance multiplier around 1 at in-plane coordinates (s, t) in metres. Deterministic in
// (seed, s, t): the same surface point looks the same from every viewpoint.
double textureValue(TextureRichness richness, uint32_t seed, double s, double t);

// A surface's own pattern; kSequence takes the sequence's TextureRichness. The periodic ones
// (floor tiles with grout, stripes, grid lines) repeat exactly every `period` metres in s and t:
// the cases where a correlator can lock onto the wrong period.
enum class SurfacePattern { kSequence, kRich, kLow, kNone, kTiles, kStripes, kGrid };
const char* toString(SurfacePattern p);

double patternValue(SurfacePattern pattern, TextureRichness sequence_texture, uint32_t seed,
                    double period, double s, double t);

}  // namespace nidevo::synth

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

}  // namespace nidevo::synth

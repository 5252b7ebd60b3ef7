#include "nidevo/sim/stress_suite.hpp"

#include <random>

namespace nidevo::synth {

SequenceConfig stressSequenceConfig(uint64_t seed) {
  std::mt19937_64 rng(seed * 0xD1B54A32D192ED03ull + 7);
  auto uniform = [&](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  SequenceConfig c;
  c.scene = "random:" + std::to_string(seed);
  c.seed = seed;
  c.frames = int(uniform(150, 301));
  const double noise = uniform(0, 1);
  c.noise = noise < 0.2   ? SensorNoise::kNone
            : noise < 0.5 ? SensorNoise::kIclLike
                          : SensorNoise::kStructuredLight;
  // ICL-NUIM's camera (fx = fy = 481.2 up to sign) or TUM fr1's.
  if (uniform(0, 1) < 0.5) {
    c.camera.fx = 517.3;
    c.camera.fy = 516.5;
    c.camera.cx = 318.6;
    c.camera.cy = 255.3;
  } else {
    c.camera.fx = 481.2;
    c.camera.fy = 481.2;
  }
  if (uniform(0, 1) < 0.5) {  // TUM's published fr1 or fr2 Kinect calibration, scaled 0.3-1
    const bool fr1 = uniform(0, 1) < 0.5;
    const double k = uniform(0.3, 1.0);
    c.camera.distortion =
        fr1 ? Distortion{0.2624 * k, -0.9531 * k, -0.0054 * k, 0.0026 * k, 1.1633 * k}
            : Distortion{0.2312 * k, -0.7849 * k, -0.0033 * k, -0.0001 * k, 0.9172 * k};
  }
  if (uniform(0, 1) < 0.5) c.exposure_jumps_per_s = uniform(0.2, 1.0);
  return c;
}

std::string describe(const SequenceConfig& c) {
  return c.scene + ", " + std::to_string(c.frames) + " frames, " + toString(c.noise) + " noise" +
         (c.camera.distortion.none() ? "" : ", distorted") +
         (c.exposure_jumps_per_s > 0 ? ", exposure jumps" : "");
}

}  // namespace nidevo::synth

#include "renders/sensor_effects.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "common/errors.h"

namespace airtwin {
namespace {

// SplitMix64's finaliser: spreads nearby seeds, frame indices and counters over unrelated bits.
uint64_t mix(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Standard normal CDF.
double normal_cdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

// Inverse-CDF sampling, already rounded to whole grey levels: entry i is the rounded Gaussian
// value (standard deviation sigma) at probability (i + 0.5) / 65536, so a uniform 16-bit index
// gives a sample of round(N(0, sigma^2)) (tails cut at ~4.3 sigma). Since pixels are whole
// numbers, adding the rounded noise is adding the noise and rounding once. Built from the CDF at
// the half-integers, so it is exact and costs O(sigma) erfc calls; cached per thread and sigma.
const std::vector<int16_t>& rounded_normal_table(double sigma) {
  thread_local double cached_sigma = -1.0;
  thread_local std::vector<int16_t> table;
  if (sigma != cached_sigma) {
    constexpr int kSize = 1 << 16;
    table.assign(kSize, 0);
    // Walk the probabilities upwards, moving to the next whole value k when p passes the CDF at
    // k + 1/2. Values beyond +-255 are clamped (they saturate any 8-bit pixel anyway).
    int k = -255;
    double next_edge = normal_cdf((k + 0.5) / sigma);
    for (int i = 0; i < kSize; ++i) {
      const double p = (i + 0.5) / kSize;
      while (p >= next_edge && k < 255) {
        ++k;
        next_edge = normal_cdf((k + 0.5) / sigma);
      }
      table[i] = static_cast<int16_t>(k);
    }
    cached_sigma = sigma;
  }
  return table;
}

}  // namespace

void validate_sensor_effects(double noise_sigma_grey, double blur_sigma_px) {
  if (!(std::isfinite(noise_sigma_grey) && noise_sigma_grey >= 0)) {
    throw InputError("render options: noise_sigma_grey must be >= 0, got " +
                     std::to_string(noise_sigma_grey));
  }
  if (!(std::isfinite(blur_sigma_px) && blur_sigma_px >= 0)) {
    throw InputError("render options: blur_sigma_px must be >= 0, got " +
                     std::to_string(blur_sigma_px));
  }
}

void apply_sensor_effects(cv::Mat& image, double noise_sigma_grey, double blur_sigma_px,
                          uint64_t seed, int64_t frame_index) {
  validate_sensor_effects(noise_sigma_grey, blur_sigma_px);
  if (image.depth() != CV_8U) {
    throw InputError("render options: sensor effects need an 8-bit image");
  }
  // Optics first: a Gaussian point-spread function, kernel out to +-3 sigma (odd size).
  if (blur_sigma_px > 0) {
    const int half = std::max(1, static_cast<int>(std::ceil(3.0 * blur_sigma_px)));
    cv::GaussianBlur(image, image, cv::Size(2 * half + 1, 2 * half + 1), blur_sigma_px,
                     blur_sigma_px, cv::BORDER_REPLICATE);
  }
  // Then the sensor: per-pixel, per-channel Gaussian noise. Sample n of the frame comes from the
  // 16-bit lane n % 4 of a hash of (seed, frame_index, n / 4): counter-based, so the noise of a
  // frame depends on nothing else, bit for bit on any platform.
  if (noise_sigma_grey > 0) {
    const std::vector<int16_t>& table = rounded_normal_table(noise_sigma_grey);
    const uint64_t key = mix(mix(seed) ^ static_cast<uint64_t>(frame_index));
    const int row_values = image.cols * image.channels();
    uint64_t counter = 0, bits = 0;
    int lane = 4;
    for (int r = 0; r < image.rows; ++r) {
      unsigned char* px = image.ptr<unsigned char>(r);
      for (int c = 0; c < row_values; ++c) {
        if (lane == 4) {
          bits = mix(key + counter++);
          lane = 0;
        }
        const int value = px[c] + table[(bits >> (16 * lane++)) & 0xFFFF];
        px[c] = static_cast<unsigned char>(std::clamp(value, 0, 255));
      }
    }
  }
}

}  // namespace airtwin

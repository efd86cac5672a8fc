#pragma once
// What the rig's camera adds to a perfect image, for robustness tests of the vision pipeline:
// optical blur (a Gaussian point-spread function) and then sensor noise (independent Gaussian
// noise per pixel and colour channel, in grey levels of the 8-bit image).
//
// Deterministic: the noise of a frame is drawn from a generator seeded by (seed, frame_index)
// alone, so the same seed and frame index give the same bytes, whatever was rendered before and
// in whichever thread; another seed or frame gives unrelated noise.

#include <cstdint>

#include <opencv2/core.hpp>

namespace airtwin {

/// Checks the two levels; throws InputError naming the field unless both are finite and >= 0.
void validate_sensor_effects(double noise_sigma_grey, double blur_sigma_px);

/// In place on an 8-bit image (any channel count): Gaussian blur of standard deviation
/// blur_sigma_px (px, kernel +-3 sigma, borders replicated), then additive Gaussian noise of
/// standard deviation noise_sigma_grey (grey levels; sampled by inverse CDF from 65536 levels, so
/// the tails stop at ~4.3 sigma), rounded and saturated to [0, 255]. A level of 0 skips that
/// effect (both 0: the image is untouched). ~3 ms of noise and ~5 ms of blur per 1024 x 1024
/// BGR frame. Throws InputError as
/// validate_sensor_effects does, and on an image that is not 8-bit.
void apply_sensor_effects(cv::Mat& image, double noise_sigma_grey, double blur_sigma_px,
                          uint64_t seed, int64_t frame_index);

}  // namespace airtwin

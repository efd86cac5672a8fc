#pragma once
// Seeded random numbers for the twin and the controller, reproducible bit for bit on any platform:
// std::mt19937_64's output sequence is fixed by the standard, and the uniform and normal
// transforms are written here (the standard library's distributions are implementation-defined).
//
// A twin derives one independent stream per purpose and object from its seed, so adding an object
// or a new effect does not shift the numbers every other object sees.

#include <cmath>
#include <cstdint>
#include <random>

namespace airtwin {

/// Streams a twin draws from (the `purpose` of RandomStream).
enum class RandomPurpose : uint64_t {
  kShape = 1,
  kHeading = 2,
  kTurbulence = 3,
  kCollection = 4,
  kController = 5,     // the CEM planner's samples
  kScenario = 6,       // randomised scenario layouts
  kAnalysis = 7,       // the discrepancy analysis's train / held-out split
  kMeasurement = 8,    // simulated instrument campaigns (models/hotwire.h)
  kObjectPhysics = 9,  // objects of one type that differ (sim/physics_variation.h)
};

class RandomStream {
 public:
  /// The stream for (seed, purpose, index): different triples give unrelated sequences.
  RandomStream(uint64_t seed, RandomPurpose purpose, uint64_t index)
      : engine_(
            mix(mix(seed) ^ mix(static_cast<uint64_t>(purpose) * 0x9E3779B97F4A7C15ull + index))) {}

  /// Uniform in (0, 1], 53 random bits.
  double uniform() { return (static_cast<double>(engine_() >> 11) + 1.0) * 0x1.0p-53; }
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * (1.0 - uniform()); }
  /// Standard normal (Box-Muller; the second value of each pair is kept for the next call).
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double radius = std::sqrt(-2.0 * std::log(uniform()));
    const double angle = 2.0 * 3.14159265358979323846 * uniform();
    spare_ = radius * std::sin(angle);
    has_spare_ = true;
    return radius * std::cos(angle);
  }

 private:
  // SplitMix64 finaliser: spreads nearby seeds over the whole 64-bit range.
  static uint64_t mix(uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  }

  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace airtwin

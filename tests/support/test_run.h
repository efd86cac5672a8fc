#pragma once
// What a test run is: its tier and its seed.
//
// The tier: CI's (the default) or the acceptance sweep's (AIRTWIN_TEST_TIER=acceptance, set by
// scripts/acceptance.sh), where the checks that need many seeds run all of them.
//
// The seed of the checks that draw their inputs at random each run (the hidden-effect magnitudes
// of the discrepancy checks): AIRTWIN_TEST_SEED when set (scripts/test.sh sets and prints it, so
// a failing run can be replayed), else one drawn from std::random_device. Either way the seed is
// printed on stdout, which ctest keeps in the log of a failed test.

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <stdexcept>
#include <string>

namespace airtwin::testing {

/// True in the acceptance tier (AIRTWIN_TEST_TIER=acceptance); false when unset. Throws
/// std::invalid_argument for any other value.
inline bool acceptance_tier() {
  const char* text = std::getenv("AIRTWIN_TEST_TIER");
  if (text == nullptr || *text == '\0' || std::string(text) == "ci") return false;
  if (std::string(text) == "acceptance") return true;
  throw std::invalid_argument(
      std::string("AIRTWIN_TEST_TIER: expected 'ci' or 'acceptance', got '") + text + "'");
}

/// The run's test seed (see above). Throws std::invalid_argument when AIRTWIN_TEST_SEED is set
/// but is not a decimal integer in [0, 2^63).
inline uint64_t test_seed() {
  static const uint64_t seed = [] {
    const char* text = std::getenv("AIRTWIN_TEST_SEED");
    uint64_t s = 0;
    if (text != nullptr && *text != '\0') {
      char* end = nullptr;
      const long long v = std::strtoll(text, &end, 10);
      if (*end != '\0' || v < 0)
        throw std::invalid_argument(std::string("AIRTWIN_TEST_SEED: expected a non-negative "
                                                "decimal integer, got '") +
                                    text + "'");
      s = static_cast<uint64_t>(v);
    } else {
      std::random_device device;
      s = (static_cast<uint64_t>(device()) << 20) ^ device();
      s &= (uint64_t{1} << 40) - 1;
    }
    std::printf("test seed: AIRTWIN_TEST_SEED=%llu replays this run\n",
                static_cast<unsigned long long>(s));
    std::fflush(stdout);
    return s;
  }();
  return seed;
}

}  // namespace airtwin::testing

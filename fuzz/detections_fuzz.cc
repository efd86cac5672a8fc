// Fuzz target: the detections CSV (models/track_join.h) that `trajectories` reads, joined with a
// fixed nozzle log in both modes: whatever the reader accepts, the join either writes
// trajectories or says why not in one InputError.

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "models/track_join.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  const std::string text = fuzz::text_of(data, size);
  static const NozzleLog nozzle =
      parse_nozzle_log("t,pan_deg,tilt_deg\n-1e9,0,10\n0.5,90,22.5\n1.0,90,22.5\n", "nozzle.csv");
  fuzz::expect_input_error([&] {
    const DetectionTable table = parse_detections_csv(text, "detections.csv");
    for (bool trials : {false, true}) {
      TrackJoinOptions options;
      options.cut_trials = trials;
      options.min_frames = 2;
      fuzz::expect_input_error(
          [&] { (void)trajectory_csv(join_tracks(table, nozzle, options).set); });
    }
  });
  return 0;
}

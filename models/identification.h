#pragma once
// Section IV end to end: measured data in, an identified object model out (what `airtwin
// identify` runs). Trajectories -> speed pairs (models/speed_pairs.h, Appendix D) -> SINDy
// (models/sindy.h) -> the end-position check (models/trajectory_replay.h) when the identified
// model has the form of eq. (8), which the predictors integrate.

#include <string>

#include "models/air_field.h"
#include "models/identified_model.h"
#include "models/sindy.h"
#include "models/speed_pairs.h"
#include "models/speed_series.h"
#include "models/trajectory_data.h"
#include "models/trajectory_replay.h"

namespace airtwin {

struct IdentificationOptions {
  SindyOptions sindy;
  SpeedPairOptions pairs;
  ReplayOptions replay;
};

/// Identifies the trajectories of `object` in `set` (the others are not used). Throws InputError
/// when `object` has no trajectory or too few usable speed pairs.
IdentifiedModel identify_trajectories(const TrajectorySet& set, const std::string& object,
                                      const AirFieldModel& field,
                                      const IdentificationOptions& options);

/// Identifies a speed series; `object` may be empty. There are no positions, so the end-position
/// MAPE is absent.
IdentifiedModel identify_series(const SpeedSeries& series, const std::string& object,
                                const IdentificationOptions& options);

}  // namespace airtwin

#pragma once
// Where the nominal model's residuals concentrate (models/discrepancy.h, step 3): every residual
// sample with its distance from s, angle, time since the command, speed and place, and their means
// in bins of each. Internal to the analysis.

#include "models/discrepancy.h"
#include "models/discrepancy_evaluation.h"
#include "models/discrepancy_windows.h"

namespace airtwin::discrepancy_detail {

// The nominal model's residuals on every window of `ws`, into report->residuals and
// report->residual_bins.
void residual_structure(const Evaluator& ev, const WindowSet& ws, DiscrepancyReport* report);

}  // namespace airtwin::discrepancy_detail

#pragma once
// Numbers as the discrepancy report prints them (models/discrepancy_report.cc writes report.json
// and report.md, declared in models/discrepancy.h). Internal to the analysis.

#include <string>

namespace airtwin::discrepancy_detail {

// `x` with `decimals` decimals, "n/a" when it is not finite.
std::string fixed(double x, int decimals);

}  // namespace airtwin::discrepancy_detail

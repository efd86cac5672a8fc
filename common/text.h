#pragma once
// Two small text helpers the parsers and records share.

#include <string>
#include <string_view>

namespace airtwin {

/// `s` without leading and trailing spaces, tabs and carriage returns.
std::string trim_blanks(std::string_view s);

/// `x` with nine significant digits ("%.9g"): short in records and messages, and read back
/// within 5e-9 relative (half a unit of the ninth digit).
std::string format_number(double x);

}  // namespace airtwin

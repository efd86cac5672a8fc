#pragma once
// Small text helpers the parsers, records and messages share.

#include <string>
#include <string_view>

namespace airtwin {

/// `s` without leading and trailing spaces, tabs and carriage returns.
std::string trim_blanks(std::string_view s);

/// `x` with nine significant digits ("%.9g"): short in records and messages, and read back
/// within 5e-9 relative (half a unit of the ninth digit).
std::string format_number(double x);

/// `x` with six significant digits ("%g"): for messages and labels people read.
std::string format_short(double x);

}  // namespace airtwin

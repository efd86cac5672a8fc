#pragma once
// Error kinds, kept apart as the style guide asks:
//  - InputError: the user gave a file, flag or field we cannot use. The message names the file,
//  line,
//    column or flag and what was expected; the CLI prints it as one line and exits with status 1.
//  - UsageError (an InputError): a command-line flag's value is unusable; exit status 2.
//  - AIRTWIN_DEMAND: a broken internal invariant (a bug), aborts loudly with file:line.

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace airtwin {

/// Bad user input: a file, a flag, a field. what() is a complete sentence naming the culprit.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

/// A flag's value is unusable (out of range, not a number, malformed pair): a usage error, exit 2.
class UsageError : public InputError {
 public:
  explicit UsageError(const std::string& message) : InputError(message) {}
};

[[noreturn]] inline void demand_failed(const char* condition, const char* file, int line) {
  std::fprintf(stderr, "airtwin: internal error: %s failed at %s:%d\n", condition, file, line);
  std::abort();
}

}  // namespace airtwin

/// Aborts with a message when an internal invariant does not hold (never for user input).
#define AIRTWIN_DEMAND(condition) \
  ((condition) ? static_cast<void>(0) : ::airtwin::demand_failed(#condition, __FILE__, __LINE__))

#pragma once
// Error kinds, kept apart as the style guide asks:
//  - InputError: the user gave a file, flag or field we cannot use. The message names the file,
//  line,
//    column or flag and what was expected; the CLI prints it as one line and exits with status 1.
//  - FieldError (an InputError): a library's options struct holds an unusable value; the
//    message names the field ("collection.per_tilt: ..."), never a flag: app/ maps the field to
//    the flag that set it (a UsageError then).
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

/// A field of a library's options is unusable: field() names it ("collection.per_tilt"),
/// detail() says what was expected and what was found.
class FieldError : public InputError {
 public:
  FieldError(const std::string& field, const std::string& detail)
      : InputError(field + ": " + detail), field_(field), detail_(detail) {}
  const std::string& field() const { return field_; }
  const std::string& detail() const { return detail_; }

 private:
  std::string field_, detail_;
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

// Error types of portcal. Templated kernels (projection, refraction, cost
// functors) never throw: they return bool or std::optional. Code above them
// throws one of these; only tools/ catches and turns them into one `error:`
// line and an exit code.
#pragma once

#include <stdexcept>
#include <string>

namespace portcal {

// Bad input from the user: names the file, image or option at fault.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An option value outside its documented range (thrown by Options::Check()).
class OptionError : public InputError {
 public:
  OptionError(const std::string& option, const std::string& value, const std::string& expected)
      : InputError("option " + option + " = " + value + ": expected " + expected) {}
  // A number as the user would type it back: "1e+300", "0.04", "5" (not
  // std::to_string's 300 digits or "0.000000").
  OptionError(const std::string& option, double value, const std::string& expected);
};

// SQLite failure: carries sqlite3_errmsg, the database path and the SQL.
class DatabaseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A solve that failed or produced a non-finite result.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The user (or a signal) asked the running stage to stop.
// By default the stage rolled back ("the database was left as it was");
// a stage that commits as it goes says what it kept.
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("cancelled; the database was left as it was") {}
  explicit Cancelled(const std::string& kept) : std::runtime_error("cancelled; " + kept) {}
};

[[noreturn]] void ThrowCheckFailure(const char* file, int line, const char* condition,
                                    const std::string& message);

}  // namespace portcal

// Programming errors (violated invariants), never user errors.
#define PORTCAL_CHECK(condition)                                        \
  do {                                                                  \
    if (!(condition)) {                                                 \
      ::portcal::ThrowCheckFailure(__FILE__, __LINE__, #condition, ""); \
    }                                                                   \
  } while (false)

#define PORTCAL_CHECK_MSG(condition, message)                                \
  do {                                                                       \
    if (!(condition)) {                                                      \
      ::portcal::ThrowCheckFailure(__FILE__, __LINE__, #condition, message); \
    }                                                                        \
  } while (false)

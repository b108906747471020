// One small exception family for the whole project (docs/ARCHITECTURE.md).
// Front ends catch at their boundary: the CLI maps UsageError to exit 2 and
// every other Error to exit 1; the viewer shows the message and keeps going.
// "Not found" (an unreachable target, say) is returned as a value, not thrown.
#pragma once

#include <stdexcept>
#include <string>

namespace vs {

// Base of everything we throw on purpose.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A file could not be read or written, or its content is malformed.
class IoError : public Error {
 public:
  using Error::Error;
};

// Well-formed input whose content is unusable (NaN voxels, empty selection...).
class DataError : public Error {
 public:
  using Error::Error;
};

// A caller broke a documented precondition (coordinates out of range, bad option).
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

// The user asked for something the command line cannot express (CLI exit status 2).
class UsageError : public InvalidArgument {
 public:
  using InvalidArgument::InvalidArgument;
};

// A long operation was cancelled through its progress hook.
class Cancelled : public Error {
 public:
  Cancelled() : Error("operation cancelled") {}
};

// Always-on precondition check: throws InvalidArgument naming the contract.
#define VS_REQUIRE(cond, msg)                                   \
  do {                                                          \
    if (!(cond)) throw ::vs::InvalidArgument(std::string(msg)); \
  } while (0)

}  // namespace vs

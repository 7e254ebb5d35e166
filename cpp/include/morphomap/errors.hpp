#pragma once
// Exceptions of the public API. The Python module turns InvalidInput into ValueError.
#include <stdexcept>
#include <string>

namespace morphomap {

// The caller passed something the algorithm cannot work with; the message names the argument.
class InvalidInput : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// A geometric computation failed on valid-looking input (a degenerate configuration, say).
class GeometryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The call stopped early because request_interrupt() was called (see interrupt.hpp).
class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("interrupted") {}
};

}  // namespace morphomap

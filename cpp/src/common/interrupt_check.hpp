#pragma once
// The poll that long loops call (a relaxed atomic load: cheap enough for every step).
namespace morphomap::detail {

// Throws Interrupted if request_interrupt() was called.
void check_interrupt();

}  // namespace morphomap::detail

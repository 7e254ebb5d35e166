#pragma once
// Stopping long work from outside: a flag that the long loops of the core (meshing, tracing,
// the pieces of a mapping) poll, so that a caller's signal handler or another thread can end a
// call within a fraction of a second. The call then throws Interrupted.
namespace morphomap {

// Async-signal-safe: may be called from a signal handler.
void request_interrupt() noexcept;
void clear_interrupt() noexcept;
bool interrupt_requested() noexcept;

}  // namespace morphomap

#pragma once
// Ctrl-C during a long call: Python's own SIGINT handler only runs once the call returns, so
// while a call runs with the GIL released this guard puts in a C handler that asks the core to
// stop (morphomap::request_interrupt); the core then throws Interrupted, which the module turns
// into KeyboardInterrupt. Only on the main thread (where Python handles signals), and only the
// outermost of nested or concurrent guards installs and restores it.
#include <pybind11/pybind11.h>

#include <morphomap/interrupt.hpp>

#include <csignal>
#include <mutex>

class InterruptGuard {
 public:
  InterruptGuard();   // with the GIL held
  ~InterruptGuard();  // likewise
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  bool installed_ = false;
};

// Records the main thread; call at module initialisation.
void record_main_thread();

#include "interrupt_guard.hpp"

#include <pythread.h>

#include <exception>

namespace {

unsigned long main_thread = 0;
int depth = 0;  // guarded by the GIL
struct sigaction previous;

extern "C" void on_interrupt(int) { morphomap::request_interrupt(); }

}  // namespace

void record_main_thread() { main_thread = PyThread_get_thread_ident(); }

InterruptGuard::InterruptGuard() {
  if (PyThread_get_thread_ident() != main_thread) return;
  if (depth++ == 0) {
    morphomap::clear_interrupt();
    struct sigaction action {};
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, &previous);
  }
  installed_ = true;
}

InterruptGuard::~InterruptGuard() {
  if (!installed_) return;
  if (--depth == 0) {
    sigaction(SIGINT, &previous, nullptr);
    // A Ctrl-C that came after the core's last poll is passed on to Python, not lost.
    if (morphomap::interrupt_requested() && std::uncaught_exceptions() == 0) PyErr_SetInterrupt();
    morphomap::clear_interrupt();
  }
}

#include <morphomap/errors.hpp>
#include <morphomap/interrupt.hpp>

#include "common/interrupt_check.hpp"

#include <atomic>

namespace morphomap {

namespace {
// Lock-free, so that setting it from a signal handler is safe.
std::atomic<bool> requested{false};
static_assert(std::atomic<bool>::is_always_lock_free);
}  // namespace

void request_interrupt() noexcept { requested.store(true, std::memory_order_relaxed); }
void clear_interrupt() noexcept { requested.store(false, std::memory_order_relaxed); }
bool interrupt_requested() noexcept { return requested.load(std::memory_order_relaxed); }

void detail::check_interrupt() {
  if (interrupt_requested()) throw Interrupted();
}

}  // namespace morphomap

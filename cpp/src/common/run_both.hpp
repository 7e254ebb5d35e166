#pragma once
// Two independent pieces of work at once (TBB: on two cores where there are two), failing as a
// sequential run would: if both throw, the first one's exception, so that which error a caller
// sees does not depend on which thread finished first.
#include <tbb/parallel_invoke.h>

#include <exception>

namespace morphomap::detail {

template <class First, class Second>
void run_both(const First& first, const Second& second) {
  std::exception_ptr failed[2];
  tbb::parallel_invoke(
      [&] {
        try {
          first();
        } catch (...) {
          failed[0] = std::current_exception();
        }
      },
      [&] {
        try {
          second();
        } catch (...) {
          failed[1] = std::current_exception();
        }
      });
  for (const std::exception_ptr& error : failed) {
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace morphomap::detail

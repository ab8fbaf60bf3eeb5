// Internal to eRMSM: arrays that a loop fills whole right after they are made.
//
// std::vector zeroes what resize() adds, on the calling thread: for the arrays of a
// fine map (megabytes for a floor's blocks) that is a memset and a page fault per 4 KB
// (~1.7 µs each on the project machine) on one thread, before the parallel loop that
// writes every element anyway. A FillVector leaves new elements of trivial types
// uninitialised, so their pages are first touched by the threads that fill them.
// Only for arrays whose every element is written before it is read.
#pragma once

#include <memory>
#include <utility>
#include <vector>

namespace mlmap {

template <typename T>
struct DefaultInitAllocator : std::allocator<T> {
  using value_type = T;
  template <typename U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <typename U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}  // NOLINT(google-explicit-constructor)

  template <typename U, typename... Args>
  void construct(U* where, Args&&... args) {
    if constexpr (sizeof...(Args) == 0) {
      ::new (static_cast<void*>(where)) U;  // default-initialised: left as it is for trivial types
    } else {
      ::new (static_cast<void*>(where)) U(std::forward<Args>(args)...);
    }
  }
};

template <typename T>
using FillVector = std::vector<T, DefaultInitAllocator<T>>;

}  // namespace mlmap

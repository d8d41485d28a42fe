#pragma once
/// @file
/// Proves that real-time code does not allocate: linking this replaces the global
/// operator new/delete with versions that count calls while a guard is active.
/// @code
///   mc::test::AllocationGuard guard;
///   for (...) model.step(...);
///   EXPECT_EQ(guard.allocations(), 0);
/// @endcode

#include <cstddef>
#include <thread>

namespace mc::test {

class AllocationGuard {
 public:
  AllocationGuard();
  /// Counts only the allocations made by `thread` (the loop's, while a server runs beside it).
  explicit AllocationGuard(std::thread::id thread);
  ~AllocationGuard();
  AllocationGuard(const AllocationGuard&) = delete;
  AllocationGuard& operator=(const AllocationGuard&) = delete;
  /// operator new calls (of any thread) since this guard was created.
  std::size_t allocations() const;

 private:
  std::size_t start_;
};

}  // namespace mc::test

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

namespace mc::test {

class AllocationGuard {
 public:
  AllocationGuard();
  ~AllocationGuard();
  AllocationGuard(const AllocationGuard&) = delete;
  AllocationGuard& operator=(const AllocationGuard&) = delete;
  /// operator new calls (of any thread) since this guard was created.
  std::size_t allocations() const;

 private:
  std::size_t start_;
};

}  // namespace mc::test

#include "support/counting_allocator.h"

#include <atomic>
#include <cstdlib>
#include <new>

#include "support/sanitizers.h"

#if MC_UNDER_TSAN
#include <sanitizer/allocator_interface.h>
#endif

namespace {
std::atomic<std::size_t> g_allocations{0};
std::atomic<int> g_active{0};
std::atomic<std::thread::id> g_only{};  // count this thread's allocations only (default id: all)

bool counted_thread() {
  const std::thread::id only = g_only.load(std::memory_order_relaxed);
  return only == std::thread::id{} || only == std::this_thread::get_id();
}

void count_allocation() {
  if (g_active.load(std::memory_order_relaxed) > 0 && counted_thread())
    g_allocations.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

#if MC_UNDER_TSAN
// ThreadSanitizer's runtime owns operator new/delete (a second definition does not link); it calls
// this hook on every allocation, new's and malloc's alike.
namespace {
void on_malloc(const volatile void*, std::size_t) { count_allocation(); }
void on_free(const volatile void*) {}
[[maybe_unused]] const int g_hooks = __sanitizer_install_malloc_and_free_hooks(on_malloc, on_free);
}  // namespace
#else
namespace {
void* counted_alloc(std::size_t size, std::size_t align) {
  count_allocation();
  if (size == 0) size = 1;
  void* p = nullptr;
  if (align > alignof(std::max_align_t)) {
    p = std::aligned_alloc(align, (size + align - 1) / align * align);
  } else {
    p = std::malloc(size);
  }
  if (!p) throw std::bad_alloc();
  return p;
}
}  // namespace

void* operator new(std::size_t size) { return counted_alloc(size, 0); }
void* operator new[](std::size_t size) { return counted_alloc(size, 0); }
void* operator new(std::size_t size, std::align_val_t a) {
  return counted_alloc(size, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t size, std::align_val_t a) {
  return counted_alloc(size, static_cast<std::size_t>(a));
}
// The nothrow forms too (std::stable_sort's temporary buffer uses them): every allocation must go
// through the same pair, or AddressSanitizer reports new/free mismatches.
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return counted_alloc(size, 0);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t& t) noexcept { return operator new(size, t); }
void* operator new(std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  try {
    return counted_alloc(size, static_cast<std::size_t>(a));
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, std::align_val_t a, const std::nothrow_t& t) noexcept {
  return operator new(size, a, t);
}
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
#endif

namespace mc::test {

AllocationGuard::AllocationGuard() : start_(g_allocations.load()) { g_active.fetch_add(1); }
AllocationGuard::AllocationGuard(std::thread::id thread) : start_(g_allocations.load()) {
  g_only.store(thread);
  g_active.fetch_add(1);
}
AllocationGuard::~AllocationGuard() {
  g_active.fetch_sub(1);
  g_only.store(std::thread::id{});
}
std::size_t AllocationGuard::allocations() const { return g_allocations.load() - start_; }

}  // namespace mc::test

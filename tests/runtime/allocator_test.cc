#include "microcobot/runtime/allocator.h"

#include <gtest/gtest.h>
#include <malloc.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <vector>

#include "support/sanitizers.h"

namespace {

// In a child process (its own malloc state): frees a 1 MiB block, the kind a camera frame is, then
// allocates 512 KiB; exits 0 when that block got a mapping of its own (mallinfo2's hblks counts
// them), 1 when it came from the heap.
int mapped_after_a_larger_free(bool keep_mapped) {
  const pid_t pid = fork();
  if (pid == 0) {
    if (keep_mapped && !mc::runtime::keep_large_blocks_mapped()) _exit(2);
    void* frame = std::malloc(1 << 20);
    *static_cast<volatile char*>(frame) = 1;
    std::free(frame);
    const std::size_t before = mallinfo2().hblks;
    void* block = std::malloc(512 << 10);
    *static_cast<volatile char*>(block) = 1;
    const bool mapped = mallinfo2().hblks == before + 1;
    std::free(block);
    _exit(mapped ? 0 : 1);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Allocator, BlocksAboveTheThresholdStayMappedAfterALargerOneIsFreed) {
  if (MC_UNDER_SANITIZER) GTEST_SKIP() << "the sanitizers' runtimes replace glibc's malloc";
  // glibc's own adjustment: freeing the mapped 1 MiB block raised the threshold past 512 KiB.
  EXPECT_EQ(mapped_after_a_larger_free(false), 1);
  EXPECT_EQ(mapped_after_a_larger_free(true), 0);
}

long resident_kib() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

// In a child process: 32 MiB of small blocks freed below one still in use (the heap's top cannot
// shrink past it); exits 0 when that memory stayed resident until release_free_pages() and left
// after it.
int freed_pages_released() {
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<void*> blocks;
    for (int i = 0; i < 32 * 1024; ++i) {
      blocks.push_back(std::malloc(1000));
      static_cast<volatile char*>(blocks.back())[0] = 1;
      static_cast<volatile char*>(blocks.back())[999] = 1;
    }
    void* in_use = std::malloc(1000);  // above them all
    static_cast<volatile char*>(in_use)[0] = 1;
    const long full = resident_kib();
    for (void* b : blocks) std::free(b);
    const long freed = resident_kib();
    const bool released = mc::runtime::release_free_pages();
    const long after = resident_kib();
    std::free(in_use);
    const bool stayed = freed > full - 8 * 1024, left = after < freed - 24 * 1024;
    _exit(stayed && released && left ? 0 : 1);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Allocator, PagesFreedBelowABlockInUseLeaveOnlyWhenReleased) {
  if (MC_UNDER_SANITIZER) GTEST_SKIP() << "the sanitizers' runtimes replace glibc's malloc";
  EXPECT_EQ(freed_pages_released(), 0);
}

}  // namespace

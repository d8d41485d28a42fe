#include "microcobot/runtime/allocator.h"

#include <gtest/gtest.h>
#include <malloc.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>

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

}  // namespace

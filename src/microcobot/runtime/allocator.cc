#include "microcobot/runtime/allocator.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace mc::runtime {

bool keep_large_blocks_mapped() {
#if defined(__GLIBC__)
  return mallopt(M_MMAP_THRESHOLD, static_cast<int>(kLargeBlockBytes)) == 1;
#else
  return false;
#endif
}

}  // namespace mc::runtime

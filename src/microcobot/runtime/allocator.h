#pragma once
/// @file
/// The C library's allocator set up for a session of hours. glibc's malloc serves a block above
/// its mmap threshold (128 KiB at start) from a mapping of its own, unmapped when it is freed; but
/// each such free raises the threshold to that block's size (up to 32 MiB), after which blocks of
/// that size come from the heap and the threads' arenas, whose freed pages stay resident while
/// any smaller block lives above them. A `serve` frees camera frames, encoded images, recording
/// chunks and client queues of a few hundred kilobytes to a few megabytes many times a second,
/// which the raised threshold leaves to the arenas, where they can fragment. Fixing the threshold
/// turns that adjustment off: such blocks are mapped and unmapped whole. Process-wide;
/// configuration-time code (call it before the threads start).

#include <cstddef>

namespace mc::runtime {

/// The size from which blocks are mapped on their own: glibc's initial threshold.
inline constexpr std::size_t kLargeBlockBytes = 128 * 1024;

/// Fixes malloc's mmap threshold at kLargeBlockBytes (mallopt M_MMAP_THRESHOLD, which also fixes
/// its trim threshold). Returns false where the C library refuses or is not glibc.
bool keep_large_blocks_mapped();

}  // namespace mc::runtime

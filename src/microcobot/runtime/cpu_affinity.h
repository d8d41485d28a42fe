#pragma once
/// @file
/// Keeping a core for the real-time loop (so that it keeps its tick): the loop's thread is pinned to
/// one core and the process's other threads (servers, drivers' buses, the camera, clients in
/// the same process) are moved off it, so that between two ticks nothing of this process runs
/// there and evicts the loop's caches and TLB entries (on a kernel with page-table isolation a
/// context switch on that core costs the next tick several microseconds). Other processes are
/// kept off by the machine's configuration (`isolcpus=` or a cpuset), not by this file.
/// Configuration-time code: it reads /proc/self/task and makes system calls.

#include <string>

namespace mc::runtime {

/// The cores this process may run on, as "0-1" or "0,2,5".
std::string allowed_cores();
/// Whether `cpu` is among them.
bool core_allowed(int cpu);
/// Pins the calling thread to `cpu`. Returns false when the kernel refuses.
bool pin_calling_thread(int cpu);
/// Removes `cpu` from the affinity of every other thread of the process that is not real-time
/// (SCHED_OTHER/BATCH/IDLE) and may run elsewhere. Threads started later inherit their
/// creator's affinity, so they keep off too. Returns the number of threads moved.
int move_other_threads_off(int cpu);
/// Gives `cpu` back to every non-real-time thread of the process, the caller's included (the
/// loop has stopped).
int give_core_back(int cpu);

}  // namespace mc::runtime

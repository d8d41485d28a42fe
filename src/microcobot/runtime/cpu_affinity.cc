#include "microcobot/runtime/cpu_affinity.h"

#include <dirent.h>
#include <pthread.h>
#include <sched.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstdlib>

namespace mc::runtime {

namespace {

bool may_use(int cpu) { return cpu >= 0 && cpu < CPU_SETSIZE; }

bool real_time(pid_t tid) {
  const int policy = sched_getscheduler(tid);
  return policy == SCHED_FIFO || policy == SCHED_RR;
}

// Applies `edit` to the affinity of every non-real-time thread of the process (but the caller's
// unless `with_caller`).
template <class Edit>
int for_threads(bool with_caller, Edit edit) {
  const auto self = static_cast<pid_t>(syscall(SYS_gettid));
  DIR* dir = opendir("/proc/self/task");
  if (dir == nullptr) return 0;
  int changed = 0;
  while (const dirent* e = readdir(dir)) {
    char* end = nullptr;
    const long tid = std::strtol(e->d_name, &end, 10);
    if (end == e->d_name || *end != '\0' || (tid == self && !with_caller) ||
        real_time(static_cast<pid_t>(tid)))
      continue;
    cpu_set_t set;
    if (sched_getaffinity(static_cast<pid_t>(tid), sizeof set, &set) != 0) continue;
    if (!edit(set)) continue;
    if (sched_setaffinity(static_cast<pid_t>(tid), sizeof set, &set) == 0) ++changed;
  }
  closedir(dir);
  return changed;
}

}  // namespace

std::string allowed_cores() {
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) != 0) return "unknown";
  std::string out;
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (!CPU_ISSET(c, &set)) continue;
    int last = c;
    while (last + 1 < CPU_SETSIZE && CPU_ISSET(last + 1, &set)) ++last;
    out += (out.empty() ? "" : ",") + std::to_string(c) + (last > c ? "-" + std::to_string(last) : "");
    c = last;
  }
  return out;
}

bool core_allowed(int cpu) {
  cpu_set_t set;
  return may_use(cpu) && sched_getaffinity(0, sizeof set, &set) == 0 && CPU_ISSET(cpu, &set);
}

bool pin_calling_thread(int cpu) {
  if (!may_use(cpu)) return false;
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  return pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
}

int move_other_threads_off(int cpu) {
  if (!may_use(cpu)) return 0;
  return for_threads(false, [cpu](cpu_set_t& set) {
    if (!CPU_ISSET(cpu, &set) || CPU_COUNT(&set) < 2) return false;  // nowhere else to go
    CPU_CLR(cpu, &set);
    return true;
  });
}

int give_core_back(int cpu) {
  if (!may_use(cpu)) return 0;
  return for_threads(true, [cpu](cpu_set_t& set) {
    if (CPU_ISSET(cpu, &set)) return false;
    CPU_SET(cpu, &set);
    return true;
  });
}

}  // namespace mc::runtime

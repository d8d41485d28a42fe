#include "signals.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>
#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstring>
#include <iostream>
#include <vector>

#include <fmt/format.h>

#include "microcobot/core/input_file.h"
#include "microcobot/core/staged_file.h"

namespace mc::cli {

namespace fs = std::filesystem;

namespace {

struct Staged {
  fs::path target;
  fs::path staging;
  std::vector<fs::path> created_parents;  ///< made by stage_output, removed on discard if empty
};

std::vector<Staged>& staged() {
  static std::vector<Staged> list;
  return list;
}

std::string& pending_stdout() {
  static std::string text;
  return text;
}

// The signal handler's copy of the staging paths (no allocation in the handler).
constexpr int kMaxStaged = 8;
char g_staging_paths[kMaxStaged][4096];
std::atomic<int> g_staging_count{0};
volatile std::sig_atomic_t g_signal = 0;
std::atomic<bool> g_cooperative{false};

// Removes `name` under directory fd `dir` recursively with async-signal-safe calls only.
void remove_tree_at(int dir, const char* name, int depth) {
  if (::unlinkat(dir, name, 0) == 0) return;
  if (depth > 16) return;
  const int fd = ::openat(dir, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return;
  alignas(8) char buf[4096];
  // Passes over the directory until one finds nothing left to remove ("." and ".." stay).
  for (int pass = 0; pass < 64; ++pass) {
    bool removed_any = false;
    ::lseek(fd, 0, SEEK_SET);
    while (true) {
      const long n = ::syscall(SYS_getdents64, fd, buf, sizeof buf);
      if (n <= 0) break;
      for (long off = 0; off < n;) {
        // struct linux_dirent64: ino (8), off (8), reclen (2), type (1), name.
        unsigned short reclen = 0;
        std::memcpy(&reclen, buf + off + 16, sizeof reclen);
        const char* entry = buf + off + 19;
        if (std::strcmp(entry, ".") != 0 && std::strcmp(entry, "..") != 0) {
          remove_tree_at(fd, entry, depth + 1);
          removed_any = true;
        }
        off += reclen;
      }
    }
    if (!removed_any) break;
  }
  ::close(fd);
  ::unlinkat(dir, name, AT_REMOVEDIR);
}

void write_stderr(const char* s) {
  const ssize_t r = ::write(2, s, std::strlen(s));
  (void)r;
}

extern "C" void on_signal(int sig) {
  if (g_cooperative.load() && g_signal == 0) {
    g_signal = sig;
    return;
  }
  write_stderr(sig == SIGINT ? "microcobot: error: interrupted (SIGINT); partial outputs removed\n"
                             : "microcobot: error: terminated (SIGTERM); partial outputs removed\n");
  const int n = g_staging_count.load();
  for (int i = 0; i < n && i < kMaxStaged; ++i) remove_tree_at(AT_FDCWD, g_staging_paths[i], 0);
  ::_exit(128 + sig);
}

}  // namespace

Interrupted::Interrupted(int signal, bool outputs_complete)
    : mc::Error(
          mc::ExitCode::kComputationFailed,
          outputs_complete
              ? fmt::format("interrupted ({}) while writing the outputs; they are complete and in place",
                            signal_name(signal))
              : fmt::format("interrupted ({}); the outputs written so far are marked as interrupted",
                            signal_name(signal))),
      signal_(signal) {}

std::string signal_name(int signal) {
  return signal == SIGINT ? "SIGINT" : signal == SIGTERM ? "SIGTERM" : fmt::format("signal {}", signal);
}

void install_signal_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
}

void set_cooperative_interrupts(bool on) { g_cooperative.store(on); }

int interrupt_signal() { return g_signal; }

fs::path stage_output(const fs::path& target_in) {
  std::string t = target_in.lexically_normal().string();
  while (t.size() > 1 && t.back() == '/') t.pop_back();
  if (t.empty()) throw InvalidInput("--out: empty directory name");
  const fs::path target = t;
  for (const auto& s : staged()) {
    if (s.target == target) return s.staging;
  }
  if (g_staging_count.load() >= kMaxStaged)
    throw InvalidInput(target.string(), 0, "too many output directories");
  std::error_code ec;
  if (fs::exists(target, ec) && !fs::is_directory(target, ec)) {
    throw InvalidInput(target.string(), 0,
                       "cannot create output directory: it exists and is not a directory");
  }
  fs::path parent = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (target.filename().empty() || target.filename() == "." || target.filename() == "..") {
    // `--out .` or `--out dir/`: stage beside the directory itself.
    parent = fs::absolute(target, ec).lexically_normal().parent_path();
  }
  Staged s;
  s.target = target;
  std::string name = fs::absolute(target, ec).lexically_normal().filename().string();
  if (name.empty()) name = "out";
  if (name.size() > NAME_MAX) {
    throw InvalidInput(target.string(), 0,
                       "cannot create output directory: " + mc::why_not_created(target, ENAMETOOLONG));
  }
  for (fs::path p = parent; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    s.created_parents.push_back(p);
    if (p == p.parent_path()) break;
  }
  fs::create_directories(parent, ec);
  if (ec || !fs::is_directory(parent)) {
    throw InvalidInput(
        target.string(), 0,
        "cannot create output directory: " + (ec ? ec.message() : std::string("not a directory")));
  }
  // The staging directory must lie on DIR's file system: the files are renamed into DIR, and a
  // rename cannot cross devices. A DIR that is a mount point (its parent on another device) is
  // staged inside itself.
  fs::path stage_in = parent;
  struct stat target_st {
  }, parent_st{};
  if (::stat(target.c_str(), &target_st) == 0 && S_ISDIR(target_st.st_mode) &&
      (::stat(parent.c_str(), &parent_st) != 0 || parent_st.st_dev != target_st.st_dev)) {
    stage_in = target;
  }
  // At most 64 bytes of DIR's name: a name near the limit (255) must leave room for the suffix.
  std::string tmpl = (stage_in / ("." + name.substr(0, 64) + ".tmp-XXXXXX")).string();
  if (::mkdtemp(tmpl.data()) == nullptr) {
    const int err = errno;
    for (const auto& p : s.created_parents) fs::remove(p, ec);
    throw InvalidInput(target.string(), 0,
                       "cannot create output directory: " + mc::why_not_created(stage_in / "x", err));
  }
  s.staging = tmpl;
  if (s.staging.string().size() < sizeof g_staging_paths[0]) {
    const int i = g_staging_count.load();
    std::strcpy(g_staging_paths[i], s.staging.c_str());
    g_staging_count.store(i + 1);
  }
  staged().push_back(s);
  return s.staging;
}

namespace {

// Every regular file under `staging`, relative; throws if the target has a conflicting entry.
void plan(const fs::path& staging, const fs::path& target, const fs::path& rel,
          std::vector<fs::path>& files) {
  for (const auto& e : fs::directory_iterator(staging / rel)) {
    const fs::path r = rel / e.path().filename();
    std::error_code ec;
    const auto dst = fs::symlink_status(target / r, ec);
    if (e.is_directory()) {
      if (fs::exists(dst) && !fs::is_directory(dst)) {
        throw InvalidInput((target / r).string(), 0,
                           "is in the way of an output directory (not a directory)");
      }
      plan(staging, target, r, files);
    } else {
      if (fs::exists(dst) && !fs::is_regular_file(dst)) {
        throw InvalidInput((target / r).string(), 0, "is in the way of an output file (not a regular file)");
      }
      files.push_back(r);
    }
  }
}

}  // namespace

void commit_outputs() {
  // Deferred, not ignored: the caller reads interrupt_signal() once every file is in place.
  const bool was_cooperative = g_cooperative.exchange(true);
  struct Restore {
    bool on;
    ~Restore() { g_cooperative.store(on); }
  } restore{was_cooperative};
  for (const auto& s : staged()) {
    std::vector<fs::path> files;
    std::error_code ec;
    if (fs::exists(s.target, ec) && !fs::is_directory(s.target, ec)) {
      throw InvalidInput(s.target.string(), 0,
                         "cannot create output directory: it exists and is not a directory");
    }
    plan(s.staging, s.target, "", files);
    fs::create_directories(s.target, ec);
    if (ec) throw InvalidInput(s.target.string(), 0, "cannot create output directory: " + ec.message());
    for (const auto& r : files) {
      fs::create_directories((s.target / r).parent_path(), ec);
      fs::rename(s.staging / r, s.target / r, ec);
      if (ec)
        throw InvalidInput((s.target / r).string(), 0, "cannot move output into place: " + ec.message());
    }
  }
  const std::string text = std::move(pending_stdout());
  discard_outputs();
  std::cout << text << std::flush;
}

void print_after_commit(const std::string& text) {
  if (staged().empty()) {
    std::cout << text << std::flush;
  } else {
    pending_stdout() += text;
  }
}

void discard_outputs() noexcept {
  std::error_code ec;
  g_staging_count.store(0);
  for (const auto& s : staged()) {
    fs::remove_all(s.staging, ec);
    for (const auto& p : s.created_parents) {
      if (fs::is_directory(p, ec) && fs::is_empty(p, ec) && !fs::exists(s.target, ec)) fs::remove(p, ec);
    }
  }
  staged().clear();
  pending_stdout().clear();
}

std::string unstaged(std::string text) {
  for (const auto& s : staged()) {
    const std::string from = s.staging.string(), to = s.target.string();
    for (std::size_t pos = 0; (pos = text.find(from, pos)) != std::string::npos; pos += to.size()) {
      text.replace(pos, from.size(), to);
    }
  }
  return text;
}

}  // namespace mc::cli

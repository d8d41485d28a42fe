#include "microcobot/core/staged_file.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <system_error>

#include "microcobot/core/error.h"

namespace mc {

std::string why_not_created(const std::filesystem::path& path, int err) {
  const std::size_t name = path.filename().string().size();
  if (name > NAME_MAX) {
    return "its name is " + std::to_string(name) + " characters long (the limit is " +
           std::to_string(NAME_MAX) + ")";
  }
  if (err == ENOENT || err == ENOTDIR) return "directory missing";
  if (err == EACCES || err == EPERM || err == EROFS) return "directory not writable";
  return std::strerror(err);
}

StagedFile::StagedFile(std::filesystem::path path) : path_(std::move(path)) {
  if (path_.filename().string().size() > NAME_MAX)
    throw InvalidInput(path_.string(), 0, "cannot write: " + why_not_created(path_, ENAMETOOLONG));
  const std::filesystem::path dir = path_.has_parent_path() ? path_.parent_path() : ".";
  // The temporary's name holds at most 64 bytes of the target's: a name near the file system's
  // limit (255) is a valid target, and its temporary must be creatable too.
  tmp_path_ = (dir / ("." + path_.filename().string().substr(0, 64) + ".XXXXXX")).string();
  fd_ = ::mkstemp(tmp_path_.data());
  if (fd_ < 0) {
    const int err = errno;
    tmp_path_.clear();
    throw InvalidInput(path_.string(), 0, "cannot write: " + why_not_created(path_, err));
  }
  // Held until the file is closed, released by the kernel when the process dies: a temporary
  // found unlocked was left by a writer that crashed (staged_file_in_use).
  ::flock(fd_, LOCK_EX | LOCK_NB);
}

bool staged_file_in_use(const std::filesystem::path& tmp) {
  const int fd = ::open(tmp.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool locked = ::flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);  // releases the lock this call may have taken
  return locked;
}

StagedFile::~StagedFile() { discard(); }

void StagedFile::discard() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (!tmp_path_.empty()) ::unlink(tmp_path_.c_str());
  tmp_path_.clear();
}

void StagedFile::fail(const std::string& what) {
  discard();
  throw InvalidInput(path_.string(), 0, what);
}

void StagedFile::write(std::string_view bytes) {
  if (fd_ < 0)
    throw InvalidInput(path_.string(), 0, committed_ ? "written after it was closed" : "abandoned");
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("write failed (disk full or not writable)");
    done += static_cast<std::size_t>(n);
  }
}

void StagedFile::commit() {
  if (committed_) return;
  if (fd_ < 0) throw InvalidInput(path_.string(), 0, "abandoned");
  bool ok = ::fsync(fd_) == 0;
  ok = (::close(fd_) == 0) && ok;
  fd_ = -1;
  // mkstemp creates 0600; output files are meant to be shared like any other.
  ok = ok && ::chmod(tmp_path_.c_str(), 0644) == 0;
  std::error_code ec;
  if (ok) std::filesystem::rename(tmp_path_, path_, ec);
  if (!ok || ec) fail("write failed (disk full or not writable)");
  tmp_path_.clear();
  committed_ = true;
}

}  // namespace mc

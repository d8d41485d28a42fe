#include "microcobot/core/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc {

namespace {

const char* file_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "is a directory, not a file";
  if (S_ISCHR(mode)) return "is a character device, not a regular file";
  if (S_ISBLK(mode)) return "is a block device, not a regular file";
  if (S_ISFIFO(mode)) return "is a FIFO (named pipe), not a regular file";
  if (S_ISSOCK(mode)) return "is a socket, not a regular file";
  return "is not a regular file";
}

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::string read_input_file(const std::filesystem::path& file, std::size_t max_bytes, std::string_view kind) {
  const std::string name = file.string();
  // stat() first: a FIFO or device is refused without opening it (opening a FIFO blocks).
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) {
    throw InvalidInput(name, 0, fmt::format("cannot open file ({})", std::strerror(errno)));
  }
  if (!S_ISREG(st.st_mode)) throw InvalidInput(name, 0, file_kind(st.st_mode));
  Fd f;
  // O_NONBLOCK: should the path have been swapped for a FIFO since stat(), open() returns.
  f.fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (f.fd < 0) throw InvalidInput(name, 0, fmt::format("cannot open file ({})", std::strerror(errno)));
  if (::fstat(f.fd, &st) != 0 || !S_ISREG(st.st_mode)) throw InvalidInput(name, 0, file_kind(st.st_mode));
  const auto too_large = [&] {
    return InvalidInput(name, 0,
                        fmt::format("file too large ({} bytes; a {} may hold at most {} bytes)",
                                    static_cast<long long>(st.st_size), kind, max_bytes));
  };
  if (st.st_size < 0 || static_cast<std::size_t>(st.st_size) > max_bytes) throw too_large();
  std::string text;
  text.resize(static_cast<std::size_t>(st.st_size));
  std::size_t got = 0;
  while (true) {
    if (got == text.size()) {
      // The file may have grown since fstat(): read on, up to the cap.
      if (text.size() > max_bytes) throw too_large();
      text.resize(std::min(max_bytes + 1, text.size() + 65536));
      if (got == text.size()) throw too_large();
    }
    const ssize_t n = ::read(f.fd, text.data() + got, text.size() - got);
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      throw InvalidInput(name, 0, fmt::format("read failed ({})", std::strerror(errno)));
    }
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  if (got > max_bytes) throw too_large();
  text.resize(got);
  return text;
}

std::string excerpt(std::string_view text, std::size_t max_chars) {
  // The cap is on the printed form: escapes count with their length.
  std::string out;
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    std::string piece;
    if (c == '\n')
      piece = "\\n";
    else if (c == '\r')
      piece = "\\r";
    else if (c == '\t')
      piece = "\\t";
    else if (c < 0x20 || c >= 0x7f)
      piece = fmt::format("\\x{:02x}", c);
    else
      piece = std::string(1, ch);
    if (out.size() + piece.size() > max_chars) {
      out += "...";
      break;
    }
    out += piece;
  }
  return out;
}

std::string fmt_number(double value) { return fmt::format("{:g}", value); }

}  // namespace mc

#include "microcobot/core/csv_stream_writer.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>

#include "microcobot/core/error.h"

namespace mc {
namespace {
constexpr std::size_t kBufferBytes = std::size_t{64} << 10;
}  // namespace

CsvStreamWriter::CsvStreamWriter(std::filesystem::path path, const std::vector<std::string>& names)
    : path_(std::move(path)), columns_(names.size()) {
  if (names.empty()) throw InvalidInput(path_.string(), 0, "a CSV file needs at least one column");
  for (const std::string& n : names)
    if (n.empty() || n.find_first_of(",\r\n") != std::string::npos)
      throw InvalidInput(path_.string(), 0, "column names must be non-empty, without ',' or line breaks");
  const std::filesystem::path dir = path_.has_parent_path() ? path_.parent_path() : ".";
  tmp_path_ = (dir / ("." + path_.filename().string() + ".XXXXXX")).string();
  fd_ = ::mkstemp(tmp_path_.data());
  if (fd_ < 0) {
    tmp_path_.clear();
    throw InvalidInput(path_.string(), 0, "cannot write (directory missing or not writable)");
  }
  buffer_.reserve(kBufferBytes + 4096);
  for (std::size_t i = 0; i < names.size(); ++i) buffer_.append(i ? "," : "").append(names[i]);
  buffer_ += '\n';
}

CsvStreamWriter::~CsvStreamWriter() {
  if (!closed_) discard();
}

void CsvStreamWriter::discard() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (!tmp_path_.empty()) ::unlink(tmp_path_.c_str());
  tmp_path_.clear();
  closed_ = true;
}

void CsvStreamWriter::fail(const std::string& what) {
  discard();
  throw InvalidInput(path_.string(), 0, what);
}

void CsvStreamWriter::flush() {
  std::size_t done = 0;
  while (done < buffer_.size()) {
    const ssize_t n = ::write(fd_, buffer_.data() + done, buffer_.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("write failed (disk full or not writable)");
    done += static_cast<std::size_t>(n);
  }
  buffer_.clear();
}

void CsvStreamWriter::append(std::span<const double> row) {
  if (closed_) throw InvalidInput(path_.string(), 0, "the file is closed or was abandoned");
  if (row.size() != columns_)
    fail("a row of " + std::to_string(row.size()) + " values for " + std::to_string(columns_) + " columns");
  char number[32];
  for (std::size_t i = 0; i < row.size(); ++i) {
    if (!std::isfinite(row[i]))
      fail("non-finite value in column " + std::to_string(i + 1) + " of row " + std::to_string(rows_ + 1));
    if (i) buffer_ += ',';
    const auto res = std::to_chars(number, number + sizeof number, row[i]);  // shortest round trip
    buffer_.append(number, res.ptr);
  }
  buffer_ += '\n';
  ++rows_;
  if (buffer_.size() >= kBufferBytes) flush();
}

void CsvStreamWriter::close() {
  if (closed_) return;
  flush();
  if (::fsync(fd_) != 0) fail("write failed (disk full or not writable)");
  const int fd = fd_;
  fd_ = -1;
  // mkstemp creates 0600; recordings are meant to be shared like any other output.
  if (::close(fd) != 0 || ::chmod(tmp_path_.c_str(), 0644) != 0)
    fail("write failed (disk full or not writable)");
  std::error_code ec;
  std::filesystem::rename(tmp_path_, path_, ec);
  if (ec) fail("cannot rename into place: " + ec.message());
  tmp_path_.clear();
  closed_ = true;
}

}  // namespace mc

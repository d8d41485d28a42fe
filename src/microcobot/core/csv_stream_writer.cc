#include "microcobot/core/csv_stream_writer.h"

#include <charconv>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc {
namespace {
constexpr std::size_t kBufferBytes = std::size_t{64} << 10;
}  // namespace

CsvStreamWriter::CsvStreamWriter(std::filesystem::path path, const std::vector<std::string>& names)
    : file_(std::move(path)), columns_(names.size()) {
  if (names.empty()) fail("a CSV file needs at least one column");
  for (const std::string& n : names)
    if (n.empty() || n.find_first_of(",\r\n") != std::string::npos)
      fail("column names must be non-empty, without ',' or line breaks");
  buffer_.reserve(kBufferBytes + 4096);
  for (std::size_t i = 0; i < names.size(); ++i) buffer_.append(i ? "," : "").append(names[i]);
  buffer_ += '\n';
}

void CsvStreamWriter::fail(const std::string& what) {
  abandoned_ = true;
  file_.discard();
  throw InvalidInput(file_.path().string(), 0, what);
}

void CsvStreamWriter::append(std::span<const double> row) {
  if (abandoned_ || file_.committed()) fail("the file is closed or was abandoned");
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
  if (buffer_.size() >= kBufferBytes) write_buffer();
}

void CsvStreamWriter::write_buffer() {
  try {
    file_.write(buffer_);  // discards the file when it fails
  } catch (...) {
    abandoned_ = true;
    throw;
  }
  buffer_.clear();
}

void CsvStreamWriter::close() {
  if (file_.committed()) return;
  if (abandoned_) fail("the file was abandoned");
  write_buffer();
  file_.commit();
}

}  // namespace mc

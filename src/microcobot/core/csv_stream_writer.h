#pragma once
/// @file
/// A CSV file written row by row, for recordings of unknown length (`serve`'s, beside the MCAP
/// file), in write_csv's format: the header of unit-suffixed names, rows of finite doubles in
/// their shortest round-trip form, so read_csv (and numpy, pandas, a spreadsheet) reads it back.
/// It is written under a temporary name beside `path` and renamed into place by close(): a
/// recording that fails or is abandoned leaves nothing under its name.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "microcobot/core/staged_file.h"

namespace mc {

class CsvStreamWriter {
 public:
  /// Creates the temporary file and writes the header. Throws InvalidInput naming `path` when
  /// the directory is missing or not writable, or a name is empty or holds a ',' or a newline.
  CsvStreamWriter(std::filesystem::path path, const std::vector<std::string>& names);
  /// Destroyed without close(), the temporary file is removed.
  CsvStreamWriter(const CsvStreamWriter&) = delete;
  CsvStreamWriter& operator=(const CsvStreamWriter&) = delete;

  /// Appends one row, one value per column. Throws InvalidInput naming the file on a row of the
  /// wrong size, a non-finite value (the reader refuses them) or a failed write; the file is
  /// then abandoned (later calls throw).
  void append(std::span<const double> row);
  /// Flushes, syncs and renames the file to its name. Throws InvalidInput on a failed write (the
  /// temporary file is then removed). Idempotent.
  void close();

  const std::filesystem::path& path() const { return file_.path(); }
  std::uint64_t rows() const { return rows_; }

 private:
  [[noreturn]] void fail(const std::string& what);
  void write_buffer();

  StagedFile file_;
  std::size_t columns_ = 0;
  std::uint64_t rows_ = 0;
  std::string buffer_;  // rows not yet written to the file
  bool abandoned_ = false;
};

}  // namespace mc

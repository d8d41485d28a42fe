#pragma once
/// @file
/// Records named channels at a fixed rate into buffers allocated up front, so that a
/// real-time loop can record without allocating, locking or doing I/O; the CSV is written
/// afterwards, outside the loop.

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "microcobot/core/csv.h"

namespace mc {

class Recorder {
 public:
  /// `channels` are unit-suffixed column names; `capacity` is the number of samples kept;
  /// one sample is kept every `decimation` calls to sample() (1 keeps all).
  Recorder(std::vector<std::string> channels, std::size_t capacity, std::size_t decimation = 1);

  /// Offers one sample (one value per channel, in order). Real-time safe: never allocates.
  /// Returns false, and counts the sample as dropped, when the buffer is full.
  bool sample(std::span<const double> values);

  std::size_t size() const { return size_; }
  std::size_t capacity() const { return capacity_; }
  std::size_t dropped() const { return dropped_; }
  std::size_t channels() const { return names_.size(); }
  /// Value of channel `c` at kept sample `i`.
  double at(std::size_t i, std::size_t c) const { return data_[i * names_.size() + c]; }
  /// A copy of channel `name` (outside the loop).
  std::vector<double> channel(const std::string& name) const;
  /// Whether a channel is called `name` (a recording of an earlier version may lack one).
  bool has_channel(const std::string& name) const;

  /// Forgets the samples, keeps the buffers.
  void clear();
  /// The kept samples as a table, and as a CSV file (atomically).
  CsvTable to_table() const;
  void write_csv(const std::filesystem::path& file) const;

 private:
  std::vector<std::string> names_;
  std::vector<double> data_;  // row-major, capacity_ x channels
  std::size_t capacity_;
  std::size_t decimation_;
  std::size_t size_ = 0;
  std::size_t countdown_ = 0;
  std::size_t dropped_ = 0;
};

}  // namespace mc

#include "microcobot/core/recorder.h"

#include <algorithm>

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc {

Recorder::Recorder(std::vector<std::string> channels, std::size_t capacity, std::size_t decimation)
    : names_(std::move(channels)), capacity_(capacity), decimation_(decimation) {
  require(!names_.empty(), "recorder.channels", "at least one channel");
  require(decimation_ >= 1, "recorder.decimation", "must be >= 1");
  data_.assign(capacity_ * names_.size(), 0.0);
}

bool Recorder::sample(std::span<const double> values) {
  if (countdown_ > 0) {
    --countdown_;
    return true;
  }
  countdown_ = decimation_ - 1;
  if (size_ >= capacity_ || values.size() != names_.size()) {
    ++dropped_;
    return false;
  }
  std::copy(values.begin(), values.end(), data_.begin() + static_cast<std::ptrdiff_t>(size_ * names_.size()));
  ++size_;
  return true;
}

bool Recorder::has_channel(const std::string& name) const {
  return std::find(names_.begin(), names_.end(), name) != names_.end();
}

std::vector<double> Recorder::channel(const std::string& name) const {
  const auto it = std::find(names_.begin(), names_.end(), name);
  if (it == names_.end()) throw InvalidInput(fmt::format("recorder: no channel '{}'", name));
  const std::size_t c = static_cast<std::size_t>(it - names_.begin());
  std::vector<double> out(size_);
  for (std::size_t i = 0; i < size_; ++i) out[i] = at(i, c);
  return out;
}

void Recorder::clear() {
  size_ = 0;
  countdown_ = 0;
  dropped_ = 0;
}

CsvTable Recorder::to_table() const {
  CsvTable t;
  for (const auto& n : names_) t.add_column(n, channel(n));
  return t;
}

void Recorder::write_csv(const std::filesystem::path& file) const { mc::write_csv(file, to_table()); }

}  // namespace mc

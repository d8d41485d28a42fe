#include "microcobot/live/camera_snapshot.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstdio>
#include <cstring>

#include "microcobot/vision/png_file.h"
#include "microcobot/vision/tiff_file.h"

namespace mc::live {
namespace {

// TIFF's ImageDescription is ASCII: the state's JSON when it is, else none.
bool printable_ascii(const std::string& s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c >= 0x20 && c < 0x7F; });
}

}  // namespace

void CameraSnapshot::offer(const platform::CameraFrame& frame, const std::string& state_json, double t_s) {
  const platform::Image& img = frame.image;
  if (img.width <= 0 || img.height <= 0 || img.data.size() != img.size_bytes()) return;
  std::lock_guard lock(mutex_);
  vision::Frame& f = kept_.frame;
  f.width = img.width;
  f.height = img.height;
  f.bit_depth = img.bit_depth;
  f.frame_index = frame.sequence;
  const std::size_t n = static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height);
  f.pixels.resize(n);
  const auto c = static_cast<std::size_t>(img.channels);
  if (img.channels == 1 && img.bit_depth > 8) {
    static_assert(std::endian::native == std::endian::little);  // Image keeps them little-endian
    std::memcpy(f.pixels.data(), img.data.data(), 2 * n);
  } else if (img.channels == 1) {
    std::copy(img.data.begin(), img.data.end(), f.pixels.begin());
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      unsigned sum = 0;
      for (std::size_t k = 0; k < c; ++k) {
        const std::size_t at = i * c + k;
        sum += img.bit_depth > 8 ? (img.data[2 * at] | (static_cast<unsigned>(img.data[2 * at + 1]) << 8))
                                 : img.data[at];
      }
      f.pixels[i] =
          static_cast<std::uint16_t>((sum + static_cast<unsigned>(c) / 2) / static_cast<unsigned>(c));
    }
  }
  kept_.m_per_px = frame.m_per_px;
  kept_.objective = frame.objective_name;
  kept_.state = state_json;
  kept_.t_s = t_s;
  kept_.valid = true;
}

std::optional<server::HttpReply> CameraSnapshot::reply(std::string_view path) const {
  if (path.substr(0, kSnapshotPath.size()) != kSnapshotPath) return std::nullopt;
  const std::string_view ext = path.substr(kSnapshotPath.size());
  if (ext != ".tiff" && ext != ".png") return std::nullopt;
  Kept copy;
  {
    std::lock_guard lock(mutex_);
    copy = kept_;
  }
  server::HttpReply r;
  if (!copy.valid) {
    r.status = 503;
    r.body = "no camera frame yet: the camera forms frames while someone watches it (open the console)\n";
    return r;
  }
  if (ext == ".tiff") {
    r.content_type = "image/tiff";
    r.body = vision::encode_tiff(copy.frame, copy.m_per_px, printable_ascii(copy.state) ? copy.state : "");
  } else {
    r.content_type = "image/png";
    r.body = vision::encode_png(copy.frame);
  }
  std::string objective;
  for (char ch : copy.objective) objective += (std::isalnum(static_cast<unsigned char>(ch)) != 0) ? ch : '-';
  char t[32];
  std::snprintf(t, sizeof t, "%.3f", copy.t_s);
  r.attachment_name = "snapshot-" + objective + "-t" + t + "s" + std::string(ext);
  return r;
}

}  // namespace mc::live

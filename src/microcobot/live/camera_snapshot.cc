#include "microcobot/live/camera_snapshot.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstdio>
#include <cstring>

#include "microcobot/devices/grey_frame.h"
#include "microcobot/imaging/png_file.h"
#include "microcobot/imaging/tiff_file.h"

namespace mc::live {
namespace {

// TIFF's ImageDescription is ASCII: the state's JSON when it is, else none.
bool printable_ascii(const std::string& s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c >= 0x20 && c < 0x7F; });
}

}  // namespace

void CameraSnapshot::offer(const devices::CameraFrame& frame, const std::string& state_json, double t_s) {
  std::lock_guard lock(mutex_);
  if (!devices::to_grey_frame(frame.image, frame.sequence, kept_.frame)) return;
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
    r.body = imaging::encode_tiff(copy.frame, copy.m_per_px, printable_ascii(copy.state) ? copy.state : "");
  } else {
    r.content_type = "image/png";
    r.body = imaging::encode_png(copy.frame);
  }
  std::string objective;
  for (char ch : copy.objective) objective += (std::isalnum(static_cast<unsigned char>(ch)) != 0) ? ch : '-';
  char t[32];
  std::snprintf(t, sizeof t, "%.3f", copy.t_s);
  r.attachment_name = "snapshot-" + objective + "-t" + t + "s" + std::string(ext);
  return r;
}

}  // namespace mc::live

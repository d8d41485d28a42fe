#include "microcobot/live/recording_recovery.h"

#include <system_error>

#include "microcobot/core/error.h"
#include "microcobot/core/mcap_recover.h"
#include "microcobot/core/staged_file.h"
#include "microcobot/live/session_recording.h"

namespace mc::live {

std::optional<std::string> unfinished_recording_stem(const std::filesystem::path& file) {
  // StagedFile's temporary: "." + the target's name + "." + six random characters.
  const std::string name = file.filename().string();
  constexpr std::string_view kExt = ".mcap.";
  const auto ext = name.rfind(kExt);
  if (name.empty() || name[0] != '.' || ext == std::string::npos || name.size() != ext + kExt.size() + 6)
    return std::nullopt;
  std::string stem = name.substr(1, ext - 1);
  if (!SessionRecording::is_stem(stem)) return std::nullopt;
  return stem;
}

std::vector<RecoveredRecording> recover_unfinished_recordings(const std::filesystem::path& dir) {
  std::vector<RecoveredRecording> out;
  std::error_code ec;
  std::vector<std::filesystem::path> found;
  for (auto it = std::filesystem::directory_iterator(dir, ec);
       !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
    std::error_code type_error;
    if (unfinished_recording_stem(it->path()) && it->is_regular_file(type_error) &&
        !staged_file_in_use(it->path()))
      found.push_back(it->path());
  }
  for (const auto& from : found) {
    RecoveredRecording r;
    r.from = from;
    const std::string stem = *unfinished_recording_stem(from);
    std::string name = stem;
    const auto taken = [&](const std::string& s) {
      std::error_code e;
      return std::filesystem::exists(dir / (s + ".mcap"), e) ||
             std::filesystem::exists(dir / (s + ".csv"), e);
    };
    for (int i = 2; taken(name) && i < 1000; ++i) name = stem + "-" + std::to_string(i);
    try {
      const McapRecovery rec = recover_mcap(from, dir / (name + ".mcap"));
      r.to = dir / (name + ".mcap");
      r.messages = rec.messages;
      r.duration_s = rec.duration_s;
      r.lost_bytes = rec.salvage.file_bytes - rec.salvage.whole_bytes;
      std::filesystem::remove(from, ec);
    } catch (const Error& e) {
      r.error = e.what();
    }
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace mc::live

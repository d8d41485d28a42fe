#pragma once
/// @file
/// Recordings a `serve` left unfinished (a crash, kill -9, a power cut): its SessionRecording
/// writes `recording-<stamp>.mcap` under the temporary `.recording-<stamp>.mcap.<random>` and
/// renames it when it stops, so one that never stopped is still a temporary. `serve` recovers
/// them at start (core/mcap_recover.h: every whole chunk, at most the last second lost), under
/// the name the recording would have had, and the console lists them as recovered.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace mc::live {

struct RecoveredRecording {
  std::filesystem::path from;  ///< the temporary file (removed once recovered)
  std::filesystem::path to;    ///< recording-<stamp>.mcap
  std::uint64_t messages = 0;
  double duration_s = 0.0;
  std::uint64_t lost_bytes = 0;  ///< the file's tail after its last whole record
  std::string error;             ///< why it could not be recovered ("" when it was; then `to` is unset)
};

/// The recording's stem a temporary file stands for ("recording-20261205-101010" for
/// ".recording-20261205-101010.mcap.Xy12Ab"), or nullopt for any other name.
std::optional<std::string> unfinished_recording_stem(const std::filesystem::path& file);

/// Recovers every unfinished recording in `dir` that no live process is writing
/// (staged_file_in_use), each to its stem's name (with "-2", "-3", ... when that is taken), and
/// removes the temporaries it recovered. One that cannot be read is left in place, with its error.
std::vector<RecoveredRecording> recover_unfinished_recordings(const std::filesystem::path& dir);

}  // namespace mc::live

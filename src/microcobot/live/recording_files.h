#pragma once
/// @file
/// The recordings folder of `serve` over HTTP (docs/console.md, "HTTP"): the list, the
/// downloads, and each recording's session report, made on demand by a worker thread:
///
///   /recordings                          {"recordings": [...]} (JSON)
///   /recordings/<stem>.mcap, .csv        downloads (409 while being written)
///   /recordings/<stem>.html              its report (202 while being made)
///   /recordings/<stem>-figures/fig-NN-<slug>.csv   the data behind the report's figures
///
/// Only these names are served (is_stem: "recording-" then digits and dashes), so a request
/// can reach no other file. The report reads the recording with the strict MCAP reader
/// (core/mcap_reader: compressed chunks too) and tells from its /events and /platform/status
/// what happened: who drove (the console or the scripted demo), e-stops, refusals, errors.

#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "microcobot/cell/session.h"
#include "microcobot/core/mcap_reader.h"
#include "microcobot/server/foxglove_server.h"

namespace mc::live {

/// What a live recording's /events and /platform/status say happened (the report's text).
cell::RecordingStory recording_story(const McapContents& mcap);

class RecordingFiles {
 public:
  /// Recordings longer than this are refused a report (the reader holds the file in memory).
  static constexpr std::uintmax_t kMaxReportRecordingBytes = 512ull << 20;
  /// Samples a report plots at most (evenly decimated).
  static constexpr std::size_t kReportSamples = 20000;

  /// `active()` names the MCAP file being written ("" when none): it is neither served nor
  /// reported. `notify(level, message)` tells the clients (a report ready or failed). The stems
  /// in `recovered` (recordings this `serve` recovered at start, live/recording_recovery.h) are
  /// listed with "recovered": true.
  RecordingFiles(std::filesystem::path dir, std::function<std::string()> active,
                 std::function<void(server::StatusLevel, const std::string&)> notify,
                 std::vector<std::string> recovered = {});
  /// Waits for a report being made.
  ~RecordingFiles();
  RecordingFiles(const RecordingFiles&) = delete;
  RecordingFiles& operator=(const RecordingFiles&) = delete;

  /// The answer to GET `path`, or nullopt (404) for a path that is not one of the above.
  std::optional<server::HttpReply> on_http(std::string_view path);
  /// The list of /recordings (JSON text).
  std::string list_json() const;
  /// Waits for a report being made (before the server goes away).
  void join();

  /// Makes the report of `stem` now, on this thread: <stem>.html and <stem>-figures/.
  /// Throws mc::Error (unreadable recording, too large).
  void make_report_now(const std::string& stem) const;

 private:
  server::HttpReply report_reply(const std::string& stem);
  void make_report(const std::string& stem);

  std::filesystem::path dir_;
  std::function<std::string()> active_;
  std::function<void(server::StatusLevel, const std::string&)> notify_;
  std::vector<std::string> recovered_;
  std::mutex mutex_;
  std::thread thread_;
  std::string reporting_;                      // the stem being made, empty when idle
  std::map<std::string, std::string> errors_;  // stem -> why its report failed
};

}  // namespace mc::live

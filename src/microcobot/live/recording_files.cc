#include "microcobot/live/recording_files.h"

#include <algorithm>
#include <system_error>

#include <nlohmann/json.hpp>

#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/live/session_recording.h"
#include "microcobot/platform/telemetry_json.h"
#include "microcobot/report/report.h"

namespace mc::live {
namespace {

using nlohmann::json;
using server::StatusLevel;

constexpr std::string_view kFigures = "-figures";

server::HttpReply html_page(int status, const std::string& title, const std::string& text, int refresh_s) {
  server::HttpReply r;
  r.status = status;
  r.content_type = "text/html; charset=utf-8";
  r.refresh_s = refresh_s;
  r.body = "<!doctype html><meta charset=\"utf-8\"><title>" + report::escape_html(title) +
           "</title><body style=\"font-family:sans-serif\"><h1>" + report::escape_html(title) + "</h1><p>" +
           report::escape_html(text) + "</p>";
  return r;
}

// A figure's CSV as report::Report names it: fig-NN-<slug>.csv, the slug [a-z0-9-].
bool is_figure_csv(std::string_view name) {
  constexpr std::string_view ext = ".csv";
  if (name.size() < 12 || name.size() > 80 || name.substr(0, 4) != "fig-" ||
      name.substr(name.size() - ext.size()) != ext)
    return false;
  const auto body = name.substr(4, name.size() - 4 - ext.size());
  return body.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-") == std::string_view::npos;
}

server::HttpReply file_reply(const std::filesystem::path& file, const std::string& type, bool download) {
  server::HttpReply r;
  r.content_type = type;
  r.file = file;
  if (download) r.attachment_name = file.filename().string();
  return r;
}

}  // namespace

cell::RecordingStory recording_story(const McapContents& mcap) {
  cell::RecordingStory story;
  if (const auto* m = mcap.find_metadata("microcobot"))
    if (const auto* v = m->find("version")) story.version = *v;
  if (const auto* m = mcap.find_metadata("scene"))
    if (const auto* v = m->find("kind")) story.scene = *v;
  std::uint16_t events = 0, status = 0;
  for (const auto& c : mcap.channels) {
    if (c.topic == "/events") events = c.id;
    if (c.topic == "/platform/status") status = c.id;
  }
  for (const auto& msg : mcap.messages) {
    if (msg.channel_id == 0 || (msg.channel_id != events && msg.channel_id != status)) continue;
    const json j = json::parse(msg.data, nullptr, /*allow_exceptions=*/false);
    if (!j.is_object()) continue;
    const double t_s = j.value("t_s", 0.0);
    if (msg.channel_id == status) {
      // The status says who drives at 5 Hz: the demo (and its phase), or a controlling client.
      if (j.value("demo", false)) {
        story.demo = true;
        const std::string phase = j.value("demo_phase", std::string());
        if (!phase.empty() && (story.demo_phases.empty() || story.demo_phases.back() != phase))
          story.demo_phases.push_back(phase);
      }
      if (j.value("controlled", false) && !story.console_control) {
        story.console_control = true;
        story.console_control_s = t_s;
      }
      continue;
    }
    const std::string kind = j.value("kind", std::string());
    const int level = j.value("level", 0);
    if (kind == "take_control" && !story.console_control) {
      story.console_control = true;
      story.console_control_s = t_s;
    }
    if (kind == "demo" || kind == "demo_phase") story.demo = true;
    if (kind == "estop") ++story.estops;
    if (kind == "refused" || kind == "protocol") ++story.refusals;
    if (level >= 2) ++story.errors;
    // The refusals of a hostile or confused client can be many: the first few tell the story.
    if ((kind == "refused" || kind == "protocol") && story.refusals > 5) continue;
    if (story.events.size() < 200)
      story.events.push_back({t_s, level, kind + ": " + j.value("message", std::string())});
  }
  return story;
}

RecordingFiles::RecordingFiles(std::filesystem::path dir, std::function<std::string()> active,
                               std::function<void(server::StatusLevel, const std::string&)> notify,
                               std::vector<std::string> recovered)
    : dir_(std::move(dir)),
      active_(std::move(active)),
      notify_(std::move(notify)),
      recovered_(std::move(recovered)) {}

RecordingFiles::~RecordingFiles() { join(); }

void RecordingFiles::join() {
  std::thread t;
  {
    std::lock_guard lock(mutex_);
    t = std::move(thread_);
  }
  if (t.joinable()) t.join();
}

std::optional<server::HttpReply> RecordingFiles::on_http(std::string_view path) {
  if (path == "/recordings") {
    server::HttpReply r;
    r.content_type = "application/json";
    r.body = list_json();
    return r;
  }
  constexpr std::string_view prefix = "/recordings/";
  if (path.substr(0, prefix.size()) != prefix) return std::nullopt;
  const std::string file(path.substr(prefix.size()));
  std::error_code ec;
  // A figure's data: <stem>-figures/fig-NN-<slug>.csv, written with the report.
  if (const auto slash = file.find('/'); slash != std::string::npos) {
    const std::string folder = file.substr(0, slash), name = file.substr(slash + 1);
    if (folder.size() <= kFigures.size() || folder.substr(folder.size() - kFigures.size()) != kFigures ||
        !SessionRecording::is_stem(std::string_view(folder).substr(0, folder.size() - kFigures.size())) ||
        !is_figure_csv(name) || !std::filesystem::is_regular_file(dir_ / folder / name, ec))
      return std::nullopt;
    return file_reply(dir_ / folder / name, "text/csv; charset=utf-8", false);
  }
  const auto dot = file.rfind('.');
  if (dot == std::string::npos || !SessionRecording::is_stem(std::string_view(file).substr(0, dot)))
    return std::nullopt;
  const std::string stem = file.substr(0, dot), ext = file.substr(dot);
  const std::string active = active_();
  if (ext == ".mcap" || ext == ".csv") {
    if (stem + ".mcap" == active)
      return html_page(409, "Recording in progress", file + " is being recorded: stop the recording first.",
                       0);
    if (!std::filesystem::is_regular_file(dir_ / file, ec)) return std::nullopt;
    return file_reply(dir_ / file, ext == ".csv" ? "text/csv; charset=utf-8" : "application/octet-stream",
                      true);
  }
  if (ext != ".html") return std::nullopt;
  if (std::filesystem::is_regular_file(dir_ / file, ec))
    return file_reply(dir_ / file, "text/html; charset=utf-8", false);
  if (stem + ".mcap" == active)
    return html_page(409, "Recording in progress",
                     stem + ".mcap is being recorded: stop the recording first.", 0);
  if (!std::filesystem::is_regular_file(dir_ / (stem + ".mcap"), ec)) return std::nullopt;
  return report_reply(stem);
}

server::HttpReply RecordingFiles::report_reply(const std::string& stem) {
  std::lock_guard lock(mutex_);
  if (const auto it = errors_.find(stem); it != errors_.end())
    return html_page(500, "No report for " + stem + ".mcap", it->second, 0);
  if (reporting_ == stem)
    return html_page(202, "Making the report of " + stem + ".mcap", "This page reloads when it is ready.", 1);
  if (!reporting_.empty())
    return html_page(503, "Busy", "Making the report of " + reporting_ + ".mcap; this page retries.", 2);
  if (thread_.joinable()) thread_.join();  // the previous one has finished
  reporting_ = stem;
  thread_ = std::thread([this, stem] { make_report(stem); });
  return html_page(202, "Making the report of " + stem + ".mcap", "This page reloads when it is ready.", 1);
}

void RecordingFiles::make_report_now(const std::string& stem) const {
  const auto mcap = dir_ / (stem + ".mcap");
  if (std::filesystem::file_size(mcap) > kMaxReportRecordingBytes)
    throw InvalidInput(mcap.string(), 0,
                       "larger than " + std::to_string(kMaxReportRecordingBytes >> 20) +
                           " MB: too long for a report (record shorter sessions)");
  const McapContents contents = read_mcap(mcap);
  const Recorder rec = platform::telemetry_from_mcap(contents, mcap.string(), kReportSamples);
  const report::Report rep = cell::recording_report(rec, stem + ".mcap", recording_story(contents));
  // The figures' CSVs first, the page last: a page that is there has its data beside it. Its
  // links are relative to /recordings/<stem>.html, so they reach the folder served above.
  const std::string figures = stem + std::string(kFigures);
  rep.write_page(dir_ / (stem + ".html"), dir_ / figures, figures + "/");
}

void RecordingFiles::make_report(const std::string& stem) {
  std::string error;
  try {
    make_report_now(stem);
    notify_(StatusLevel::kInfo, "report ready: /recordings/" + stem + ".html");
  } catch (const std::exception& e) {
    error = e.what();
    notify_(StatusLevel::kError, "report of " + stem + ".mcap: " + error);
  }
  std::lock_guard lock(mutex_);
  if (!error.empty()) errors_[stem] = error;
  reporting_.clear();
}

std::string RecordingFiles::list_json() const {
  const std::string active = active_();
  json list = json::array();
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator(dir_, ec);
       !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
    const auto& p = it->path();
    if (p.extension() != ".mcap" || !SessionRecording::is_stem(p.stem().string()) || !it->is_regular_file(ec))
      continue;
    const std::string name = p.filename().string(), stem = p.stem().string();
    std::error_code size_error, other;
    const auto size = it->file_size(size_error);
    const bool has_report = std::filesystem::is_regular_file(dir_ / (stem + ".html"), other);
    const bool has_csv = std::filesystem::is_regular_file(dir_ / (stem + ".csv"), other);
    list.push_back(
        {{"name", name},
         {"bytes", size_error ? 0 : size},
         {"recording", false},
         {"url", "/recordings/" + name},
         {"csv_url", has_csv ? json("/recordings/" + stem + ".csv") : json(nullptr)},
         {"report_url", "/recordings/" + stem + ".html"},
         {"report_ready", has_report},
         {"recovered", std::find(recovered_.begin(), recovered_.end(), stem) != recovered_.end()}});
  }
  if (!active.empty()) {  // written under a temporary name until it is closed
    list.push_back({{"name", active},
                    {"bytes", 0},
                    {"recording", true},
                    {"url", nullptr},
                    {"csv_url", nullptr},
                    {"report_url", nullptr},
                    {"report_ready", false},
                    {"recovered", false}});
  }
  std::sort(list.begin(), list.end(), [](const json& a, const json& b) { return a["name"] > b["name"]; });
  return json{{"recordings", list}}.dump();
}

}  // namespace mc::live

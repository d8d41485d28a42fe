#include "microcobot/live/console_server.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <system_error>
#include <vector>

#include <nlohmann/json.hpp>

#include "microcobot/core/csv.h"
#include "microcobot/core/csv_stream_writer.h"
#include "microcobot/core/error.h"
#include "microcobot/core/mcap_writer.h"
#include "microcobot/dsp/butterworth.h"
#include "microcobot/live/console_page.h"
#include "microcobot/platform/session.h"
#include "microcobot/platform/telemetry_json.h"

namespace mc::live {
namespace {

using nlohmann::json;
using server::StatusLevel;

constexpr double kTelemetryRate_Hz = 1000.0;  // the platform's telemetry task (loop.telemetry_divisor)

std::size_t channel_index(const char* name) {
  for (std::size_t i = 0; i < platform::kTelemetryChannels.size(); ++i)
    if (std::string_view(platform::kTelemetryChannels[i]) == name) return i;
  return 0;
}
const std::size_t kContactX = channel_index("contact_x_N");
const std::size_t kGrip = channel_index("grip_force_N");
const std::size_t kTick = channel_index("tick_us");
const std::size_t kTickCpu = channel_index("tick_cpu_us");

std::string schema(const json& properties) {
  return json{{"type", "object"}, {"properties", properties}}.dump();
}

// With only some properties always present (the others depend on the scene).
std::string schema(const json& properties, const std::vector<std::string>& required) {
  return json{{"type", "object"}, {"properties", properties}, {"required", required}}.dump();
}

// A recording's stem: "recording-" then digits and dashes (what start_recording() names), so a
// request can name nothing else (no path, no hidden or temporary file).
bool is_recording_stem(std::string_view stem) {
  constexpr std::string_view prefix = "recording-";
  if (stem.size() <= prefix.size() || stem.size() > 64 || stem.substr(0, prefix.size()) != prefix)
    return false;
  return stem.find_first_not_of("0123456789-", prefix.size()) == std::string_view::npos;
}

std::string html_escape(std::string_view text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

server::HttpReply html_page(int status, const std::string& title, const std::string& text, int refresh_s) {
  server::HttpReply r;
  r.status = status;
  r.content_type = "text/html; charset=utf-8";
  r.refresh_s = refresh_s;
  r.body = "<!doctype html><meta charset=\"utf-8\"><title>" + html_escape(title) +
           "</title><body style=\"font-family:sans-serif\"><h1>" + html_escape(title) + "</h1><p>" +
           html_escape(text) + "</p>";
  return r;
}

dsp::SosFilter rumble_filter(double fc_Hz) {
  return dsp::SosFilter(dsp::linkwitz_riley(4, fc_Hz, kTelemetryRate_Hz, dsp::FilterType::kHighPass));
}

}  // namespace

void ConsoleServerParams::validate() const {
  server.validate();
  require(std::isfinite(telemetry_rate_Hz) && telemetry_rate_Hz >= 1 && telemetry_rate_Hz <= 1000,
          "telemetry_rate_Hz", "must be within [1, 1000] Hz", telemetry_rate_Hz);
  require(std::isfinite(status_rate_Hz) && status_rate_Hz >= 0.5 && status_rate_Hz <= 100, "status_rate_Hz",
          "must be within [0.5, 100] Hz", status_rate_Hz);
  require(std::isfinite(rumble_crossover_Hz) && rumble_crossover_Hz > 0 && rumble_crossover_Hz < 450,
          "rumble_crossover_Hz", "must be within (0, 450) Hz (below the telemetry's Nyquist)",
          rumble_crossover_Hz);
  require(std::isfinite(rumble_full_scale_N) && rumble_full_scale_N > 0, "rumble_full_scale_N", "must be > 0",
          rumble_full_scale_N);
}

ConsoleServer::ConsoleServer(LivePlatform& live, ConsoleServerParams params)
    : live_(live),
      params_((params.validate(), std::move(params))),
      server_(params_.server, "microcobot",
              {{"/", {"text/html; charset=utf-8", console_page()}},
               {"/index.html", {"text/html; charset=utf-8", console_page()}}}),
      rumble_x_(rumble_filter(params_.rumble_crossover_Hz)),
      rumble_y_(rumble_filter(params_.rumble_crossover_Hz)),
      rumble_z_(rumble_filter(params_.rumble_crossover_Hz)) {
  decimation_ =
      static_cast<std::size_t>(std::max(1.0, std::round(kTelemetryRate_Hz / params_.telemetry_rate_Hz)));
  telemetry_ch_ = server_.add_channel({std::string(platform::kTelemetryTopic), "json",
                                       std::string(platform::kTelemetrySchemaName), "jsonschema",
                                       platform::telemetry_json_schema(live_.channel_count())});
  const json number = {{"type", "number"}}, boolean = {{"type", "boolean"}}, text = {{"type", "string"}};
  status_ch_ = server_.add_channel({"/platform/status", "json", "microcobot.Status", "jsonschema",
                                    schema({{"t_s", number},
                                            {"estopped", boolean},
                                            {"controlled", boolean},
                                            {"console_fresh", boolean},
                                            {"demo", boolean},
                                            {"demo_phase", text},
                                            {"lifecycle", {{"type", "object"}}},
                                            {"overruns", number},
                                            {"tick_p99_us", number},
                                            {"tick_cpu_p99_us", number},
                                            {"command_latency_ms", {{"type", "object"}}},
                                            {"link_cost_us", {{"type", "object"}}},
                                            {"clients", number},
                                            {"recording", {{"type", {"string", "null"}}}},
                                            {"last_error", text},
                                            {"ticks", number},
                                            {"demo_result", {{"type", {"object", "null"}}}}})});
  const json vec3 = {{"type", "array"}, {"items", number}, {"minItems", 3}, {"maxItems", 3}};
  // The optical-trap scene adds its beads; the pick-and-place keys are always there.
  const std::vector<std::string> scene_keys = {"kind",
                                               "part_side_m",
                                               "part_height_m",
                                               "hole_side_m",
                                               "hole_depth_m",
                                               "target_m",
                                               "tolerance_m",
                                               "max_opening_m",
                                               "finger_width_m",
                                               "workspace_min_m",
                                               "workspace_max_m",
                                               "max_speed_m_s",
                                               "force_full_scale_N",
                                               "grip_force_limit_N",
                                               "contact_force_limit_N",
                                               "demo_available",
                                               "demo_unavailable_reason"};
  scene_ch_ = server_.add_channel({"/platform/scene", "json", "microcobot.Scene", "jsonschema",
                                   schema({{"kind", text},
                                           {"part_side_m", number},
                                           {"part_height_m", number},
                                           {"hole_side_m", number},
                                           {"hole_depth_m", number},
                                           {"target_m", vec3},
                                           {"tolerance_m", number},
                                           {"max_opening_m", number},
                                           {"finger_width_m", number},
                                           {"workspace_min_m", vec3},
                                           {"workspace_max_m", vec3},
                                           {"max_speed_m_s", number},
                                           {"force_full_scale_N", number},
                                           {"grip_force_limit_N", number},
                                           {"contact_force_limit_N", number},
                                           {"demo_available", boolean},
                                           {"demo_unavailable_reason", text},
                                           {"bead_radius_m", number},
                                           {"obstacle_m", {{"type", "array"}, {"items", number}}},
                                           {"obstacle_radius_m", number}},
                                          scene_keys)});
  feedback_ch_ = server_.add_channel({"/console/feedback", "json", "microcobot.Feedback", "jsonschema",
                                      schema({{"contact_N", vec3}, {"grip_N", number}, {"rumble", number}})});
  server_.on_client_message([this](const server::ClientMessage& m) { on_message(m); });
  server_.on_disconnect([this](server::ClientId c) { on_disconnect(c); });
  server_.on_http_get([this](std::string_view path) { return on_http(path); });
  json_.reserve(4096);
}

ConsoleServer::~ConsoleServer() { stop(); }

std::string ConsoleServer::url() const {
  std::string host = params_.server.address;
  // Listening on every interface: this machine opens it on loopback.
  if (host == "0.0.0.0") host = "127.0.0.1";
  if (host == "::") host = "::1";
  if (host.find(':') != std::string::npos) host = "[" + host + "]";
  std::string u = "http://" + host + ":" + std::to_string(server_.port()) + "/";
  if (!params_.server.token.empty()) u += "?token=" + params_.server.token;
  return u;
}

void ConsoleServer::start() {
  server_.start();
  live_.start([this](const platform::TelemetrySample& s, std::size_t count) { on_sample(s, count); });
  status_ = std::thread([this] { status_thread(); });
  started_ = true;
}

void ConsoleServer::stop() {
  if (!started_) return;
  started_ = false;
  quit_.store(true);
  if (status_.joinable()) status_.join();
  live_.stop();  // every device to its safe state; the drain has delivered its last sample
  try {
    stop_recording();
  } catch (const std::exception&) {
    // The recording could not be finished (disk full): its temporary file is gone; stopping
    // goes on regardless.
  }
  server_.stop();  // no more requests: no new report
  if (report_thread_.joinable()) report_thread_.join();
}

void ConsoleServer::on_sample(const platform::TelemetrySample& s, std::size_t count) {
  const std::span<const double> sample(s.data(), count);
  {
    std::lock_guard lock(recording_mutex_);
    if (recording_) {
      json_.clear();
      platform::telemetry_to_json(sample, json_);
      const auto ns = static_cast<std::uint64_t>(std::llround(std::max(0.0, s[0]) * 1e9));
      try {
        recording_->write(recording_channel_, ns, ns, json_);
        recording_csv_->append(sample);
      } catch (const std::exception& e) {
        server_.broadcast_status(StatusLevel::kError, std::string("recording stopped: ") + e.what());
        recording_.reset();  // removes the temporary files; nothing half-written remains
        recording_csv_.reset();
        recording_name_.clear();
      }
    }
  }
  ticks_.add(s[kTick] * 1e-6);
  ticks_cpu_.add(s[kTickCpu] * 1e-6);
  if (ticks_.count() >= 1000) {  // the loop's tick p99 over the last second
    tick_p99_us_.store(1e6 * ticks_.quantile_s(0.99));
    tick_cpu_p99_us_.store(1e6 * ticks_cpu_.quantile_s(0.99));
    ticks_.reset();
    ticks_cpu_.reset();
  }
  const double hx = rumble_x_.process(s[kContactX]), hy = rumble_y_.process(s[kContactX + 1]),
               hz = rumble_z_.process(s[kContactX + 2]);
  rumble_sum_ += hx * hx + hy * hy + hz * hz;
  ++rumble_n_;
  if (countdown_ > 0) {
    --countdown_;
    return;
  }
  countdown_ = decimation_ - 1;
  const auto ns = static_cast<std::uint64_t>(std::llround(std::max(0.0, s[0]) * 1e9));
  json_.clear();
  platform::telemetry_to_json(sample, json_);
  server_.publish(telemetry_ch_, ns, json_);
  const double rms = rumble_n_ ? std::sqrt(rumble_sum_ / static_cast<double>(rumble_n_)) : 0.0;
  rumble_sum_ = 0.0;
  rumble_n_ = 0;
  const double rumble = std::isfinite(rms) ? std::min(1.0, rms / params_.rumble_full_scale_N) : 0.0;
  auto finite = [](double v) { return std::isfinite(v) ? v : 0.0; };
  const json f = {{"contact_N", {finite(s[kContactX]), finite(s[kContactX + 1]), finite(s[kContactX + 2])}},
                  {"grip_N", finite(s[kGrip])},
                  {"rumble", rumble}};
  server_.publish(feedback_ch_, ns, f.dump());
}

void ConsoleServer::on_message(const server::ClientMessage& m) {
  const server::ClientId controller = controller_.load();
  try {
    if (m.topic == "/console/command") {
      ConsoleCommand c = parse_console_command(m.payload, live_.limits());
      c.received_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                          std::chrono::steady_clock::now().time_since_epoch())
                          .count();
      if (m.client != controller) {
        server_.send_status(m.client, StatusLevel::kWarning, "control: take control first; command ignored",
                            "control");
        return;
      }
      if (!live_.push_command(c))
        server_.send_status(m.client, StatusLevel::kWarning,
                            "/console/command: the loop is busy; command dropped", "/console/command");
      return;
    }
    if (m.topic != "/console/action") {
      server_.send_status(m.client, StatusLevel::kError,
                          "unknown topic '" + std::string(m.topic.substr(0, 80)) +
                              "': the console publishes /console/command and /console/action",
                          "unknown-topic");
      return;
    }
    const ConsoleAction a = parse_console_action(m.payload);
    switch (a) {
      case ConsoleAction::kEstop:  // anyone may stop the platform
        live_.estop();
        server_.broadcast_status(StatusLevel::kWarning, "e-stop pressed: every device in its safe state");
        return;
      case ConsoleAction::kTakeControl: {
        const server::ClientId previous = controller_.exchange(m.client);
        if (previous != 0 && previous != m.client)
          server_.send_status(previous, StatusLevel::kInfo, "control: taken by another client", "control");
        live_.push_command(ConsoleCommand{});  // the new controller starts from rest
        live_.set_console_in_control(true);
        server_.send_status(m.client, StatusLevel::kInfo, "control: granted", "control");
        return;
      }
      case ConsoleAction::kReleaseControl:
        if (m.client == controller) on_disconnect(m.client);
        server_.send_status(m.client, StatusLevel::kInfo, "control: released", "control");
        return;
      case ConsoleAction::kRecordStart:
        start_recording();
        server_.broadcast_status(StatusLevel::kInfo, "recording to " + recording_name_);
        return;
      case ConsoleAction::kRecordStop:
        stop_recording();
        server_.broadcast_status(StatusLevel::kInfo, "recording stopped");
        return;
      case ConsoleAction::kReset:
      case ConsoleAction::kDemo:
      case ConsoleAction::kRestart:
        if (m.client != controller) {
          server_.send_status(m.client, StatusLevel::kWarning, "control: take control first; action ignored",
                              "control");
          return;
        }
        live_.request(a);
        return;
    }
  } catch (const Error& e) {
    // The status names what it refuses (its id is the offending message's topic), so a client
    // can tell which of its messages it concerns.
    server_.send_status(m.client, StatusLevel::kError, e.what(), std::string(m.topic.substr(0, 80)));
  }
}

void ConsoleServer::on_disconnect(server::ClientId client) {
  server::ClientId expected = client;
  if (controller_.compare_exchange_strong(expected, 0)) {
    // Nobody controls: the loop's watchdog sees stale commands and the stage holds.
    live_.set_console_in_control(false);
  }
}

void ConsoleServer::start_recording() {
  if (params_.out_dir.empty()) throw InvalidInput("recording is disabled: serve was started without --out");
  std::lock_guard lock(recording_mutex_);
  if (recording_) return;
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "recording-%Y%m%d-%H%M%S", &tm);
  std::string stem = stamp;
  const auto taken = [&](const std::string& s) {
    return std::filesystem::exists(params_.out_dir / (s + ".mcap")) ||
           std::filesystem::exists(params_.out_dir / (s + ".csv"));
  };
  for (int i = 2; taken(stem) && i < 1000; ++i)
    stem = std::string(stamp) + "-" + std::to_string(i);  // same second
  auto w = std::make_unique<McapWriter>(params_.out_dir / (stem + ".mcap"));
  const auto schema_id = w->add_schema(platform::kTelemetrySchemaName, "jsonschema",
                                       platform::telemetry_json_schema(live_.channel_count()));
  recording_channel_ = w->add_channel(schema_id, platform::kTelemetryTopic, "json");
  recording_csv_ = std::make_unique<CsvStreamWriter>(
      params_.out_dir / (stem + ".csv"),
      std::vector<std::string>(
          platform::kTelemetryChannels.begin(),
          platform::kTelemetryChannels.begin() + static_cast<std::ptrdiff_t>(live_.channel_count())));
  recording_ = std::move(w);
  recording_name_ = stem + ".mcap";
}

void ConsoleServer::stop_recording() {
  std::unique_ptr<McapWriter> w;
  std::unique_ptr<CsvStreamWriter> csv;
  {
    std::lock_guard lock(recording_mutex_);
    w = std::move(recording_);
    csv = std::move(recording_csv_);
    recording_name_.clear();
  }
  if (w) w->close();      // summary, index, footer; then renamed to its name
  if (csv) csv->close();  // (a failed MCAP leaves its CSV abandoned: neither file appears)
}

std::string ConsoleServer::scene_json() const {
  const auto& c = live_.limits();
  json j{{"kind", "pick-place"},
         {"part_side_m", live_.part_side_m()},
         {"part_height_m", live_.part_height_m()},
         {"hole_side_m", live_.hole_side_m()},
         {"hole_depth_m", live_.hole_depth_m()},
         {"target_m", live_.target_m()},
         {"tolerance_m", live_.placement_tolerance_m()},
         {"max_opening_m", c.max_opening_m},
         {"finger_width_m", live_.finger_width_m()},
         {"workspace_min_m", c.min_m},
         {"workspace_max_m", c.max_m},
         {"max_speed_m_s", c.max_speed_m_s},
         // The gauges' full scales are the limits the platform enforces (issue #26).
         {"force_full_scale_N", live_.contact_force_limit_N()},
         {"grip_force_limit_N", live_.grip_force_limit_N()},
         {"contact_force_limit_N", live_.contact_force_limit_N()}};
  const std::string no_demo = live_.demo_unavailable_reason();
  j["demo_available"] = no_demo.empty();
  j["demo_unavailable_reason"] = no_demo;
  if (live_.optical_trap_scene()) {
    // The probe bead (the telemetry's part_* channels) and the stuck bead; forces in piconewtons:
    // the gauge's full scale is the trap's escape force, k times the probe's radius.
    const auto& trap = live_.optical_trap().trap;
    j["kind"] = "optical-trap";
    j["bead_radius_m"] = trap.bead_radius_m;
    j["obstacle_m"] = live_.obstacle_m();
    j["obstacle_radius_m"] = trap.obstacle_radius_m;
    j["force_full_scale_N"] = trap.trap_stiffness_N_per_m * trap.bead_radius_m;
  }
  return j.dump();
}

std::string ConsoleServer::status_json() {
  const LiveStatus s = live_.status();
  json lifecycle = json::object();
  const char* names[6] = {"axis_x", "axis_y", "axis_z", "gripper", "haptic", "tweezers"};
  for (std::size_t i = 0; i < 6; ++i) lifecycle[names[i]] = std::string(platform::to_string(s.lifecycle[i]));
  std::string recording;
  {
    std::lock_guard lock(recording_mutex_);
    recording = recording_name_;
  }
  json j = {{"t_s", s.t_s},
            {"estopped", s.estopped},
            {"controlled", controller_.load() != 0},
            {"console_fresh", s.console_fresh},
            {"demo", s.demo},
            {"demo_phase", s.demo_phase},
            {"lifecycle", lifecycle},
            {"overruns", s.overruns},
            {"tick_p99_us", tick_p99_us_.load()},
            {"tick_cpu_p99_us", tick_cpu_p99_us_.load()},
            {"command_latency_ms",
             {{"count", latency_.count()},
              {"p50", 1e3 * latency_.quantile_s(0.5)},
              {"p99", 1e3 * latency_.quantile_s(0.99)},
              {"max", 1e3 * latency_.max_s()}}},
            {"link_cost_us",
             {{"count", link_cost_.count()},
              {"p50", 1e6 * link_cost_.quantile_s(0.5)},
              {"p99", 1e6 * link_cost_.quantile_s(0.99)},
              {"max", 1e6 * link_cost_.max_s()}}},
            {"clients", server_.client_count()},
            {"recording", recording.empty() ? json(nullptr) : json(recording)},
            {"last_error", s.last_error},
            {"ticks", s.ticks}};
  const DemoResult& d = s.demo_result;
  if (d.outcome == DemoResult::Outcome::kNone) {
    j["demo_result"] = nullptr;
  } else {
    j["demo_result"] = {{"outcome", DemoResult::name(d.outcome)},
                        {"phase", d.phase},
                        {"placement_error_m", std::isfinite(d.placement_error_m) ? json(d.placement_error_m) : json(nullptr)},
                        {"reason", d.reason},
                        {"duration_s", d.duration_s}};
  }
  return j.dump();
}

void ConsoleServer::status_thread() {
  const auto period = std::chrono::duration<double>(1.0 / params_.status_rate_Hz);
  auto next = std::chrono::steady_clock::now();
  int n = 0;
  while (!quit_.load()) {
    next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
    // A thread kept off the CPU for several periods resumes on time rather than publishing the
    // missed statuses back to back (each would repeat the same figures).
    const auto now = std::chrono::steady_clock::now();
    if (next < now) next = now;
    std::this_thread::sleep_until(next);
    const auto ns = static_cast<std::uint64_t>(std::llround(live_.status().t_s * 1e9));
    live_.drain_command_latencies(latency_);
    live_.drain_link_costs(link_cost_);
    server_.publish(status_ch_, ns, status_json());
    if (n++ % static_cast<int>(std::max(1.0, params_.status_rate_Hz)) == 0)
      server_.publish(scene_ch_, ns, scene_json());
  }
}

// ---------------------------------------------------------------------------------------------
// Recordings over HTTP, and their reports on demand.

std::optional<server::HttpReply> ConsoleServer::on_http(std::string_view path) {
  if (params_.out_dir.empty()) return std::nullopt;
  if (path == "/recordings") {
    server::HttpReply r;
    r.content_type = "application/json";
    r.body = recordings_json();
    return r;
  }
  constexpr std::string_view prefix = "/recordings/";
  if (path.substr(0, prefix.size()) != prefix) return std::nullopt;
  const std::string file(path.substr(prefix.size()));
  const auto dot = file.rfind('.');
  if (dot == std::string::npos || !is_recording_stem(std::string_view(file).substr(0, dot)))
    return std::nullopt;
  const std::string stem = file.substr(0, dot), ext = file.substr(dot);
  std::string active;
  {
    std::lock_guard lock(recording_mutex_);
    active = recording_name_;
  }
  std::error_code ec;
  if (ext == ".mcap" || ext == ".csv") {
    if (stem + ".mcap" == active)
      return html_page(409, "Recording in progress", file + " is being recorded: stop the recording first.",
                       0);
    if (!std::filesystem::is_regular_file(params_.out_dir / file, ec)) return std::nullopt;
    server::HttpReply r;
    r.content_type = ext == ".csv" ? "text/csv; charset=utf-8" : "application/octet-stream";
    r.file = params_.out_dir / file;
    r.attachment_name = file;
    return r;
  }
  if (ext != ".html") return std::nullopt;
  if (std::filesystem::is_regular_file(params_.out_dir / file, ec)) {
    server::HttpReply r;
    r.content_type = "text/html; charset=utf-8";
    r.file = params_.out_dir / file;
    return r;
  }
  if (stem + ".mcap" == active)
    return html_page(409, "Recording in progress",
                     stem + ".mcap is being recorded: stop the recording first.", 0);
  if (!std::filesystem::is_regular_file(params_.out_dir / (stem + ".mcap"), ec)) return std::nullopt;
  return report_reply(stem);
}

server::HttpReply ConsoleServer::report_reply(const std::string& stem) {
  std::lock_guard lock(report_mutex_);
  if (const auto it = report_errors_.find(stem); it != report_errors_.end())
    return html_page(500, "No report for " + stem + ".mcap", it->second, 0);
  if (reporting_ == stem)
    return html_page(202, "Making the report of " + stem + ".mcap", "This page reloads when it is ready.", 1);
  if (!reporting_.empty())
    return html_page(503, "Busy", "Making the report of " + reporting_ + ".mcap; this page retries.", 2);
  if (report_thread_.joinable()) report_thread_.join();  // the previous one has finished
  reporting_ = stem;
  report_thread_ = std::thread([this, stem] { make_report(stem); });
  return html_page(202, "Making the report of " + stem + ".mcap", "This page reloads when it is ready.", 1);
}

void ConsoleServer::make_report(const std::string& stem) {
  const auto mcap = params_.out_dir / (stem + ".mcap");
  std::string error;
  try {
    if (std::filesystem::file_size(mcap) > kMaxReportRecordingBytes)
      throw InvalidInput(mcap.string(), 0,
                         "larger than " + std::to_string(kMaxReportRecordingBytes >> 20) +
                             " MB: too long for a report (record shorter sessions)");
    const Recorder rec = platform::read_telemetry_mcap(mcap, kReportSamples);
    write_file_atomic(params_.out_dir / (stem + ".html"),
                      platform::recording_report(rec, stem + ".mcap").html());
    server_.broadcast_status(StatusLevel::kInfo, "report ready: /recordings/" + stem + ".html", "report");
  } catch (const std::exception& e) {
    error = e.what();
    server_.broadcast_status(StatusLevel::kError, "report of " + stem + ".mcap: " + error, "report");
  }
  std::lock_guard lock(report_mutex_);
  if (!error.empty()) report_errors_[stem] = error;
  reporting_.clear();
}

std::string ConsoleServer::recordings_json() const {
  std::string active;
  {
    std::lock_guard lock(recording_mutex_);
    active = recording_name_;
  }
  json list = json::array();
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator(params_.out_dir, ec);
       !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
    const auto& p = it->path();
    if (p.extension() != ".mcap" || !is_recording_stem(p.stem().string()) || !it->is_regular_file(ec))
      continue;
    const std::string name = p.filename().string();
    std::error_code size_error, report_error;
    const auto size = it->file_size(size_error);
    const std::uintmax_t bytes = size_error ? 0 : size;
    const bool has_report =
        std::filesystem::is_regular_file(params_.out_dir / (p.stem().string() + ".html"), report_error);
    const std::string csv = p.stem().string() + ".csv";
    const bool has_csv = std::filesystem::is_regular_file(params_.out_dir / csv, report_error);
    list.push_back({{"name", name},
                    {"bytes", bytes},
                    {"recording", false},
                    {"url", "/recordings/" + name},
                    {"csv_url", has_csv ? json("/recordings/" + csv) : json(nullptr)},
                    {"report_url", "/recordings/" + p.stem().string() + ".html"},
                    {"report_ready", has_report}});
  }
  if (!active.empty()) {  // written under a temporary name until it is closed
    list.push_back({{"name", active},
                    {"bytes", 0},
                    {"recording", true},
                    {"url", nullptr},
                    {"csv_url", nullptr},
                    {"report_url", nullptr},
                    {"report_ready", false}});
  }
  std::sort(list.begin(), list.end(), [](const json& a, const json& b) { return a["name"] > b["name"]; });
  return json{{"recordings", list}}.dump();
}

}  // namespace mc::live

#include "microcobot/live/console_server.h"

#include <chrono>
#include <cmath>
#include <ctime>

#include <nlohmann/json.hpp>

#include "microcobot/core/error.h"
#include "microcobot/core/mcap_writer.h"
#include "microcobot/dsp/butterworth.h"
#include "microcobot/live/console_page.h"
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

std::string schema(const json& properties) {
  return json{{"type", "object"}, {"properties", properties}}.dump();
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
                                            {"clients", number},
                                            {"recording", {{"type", {"string", "null"}}}},
                                            {"last_error", text}})});
  const json vec3 = {{"type", "array"}, {"items", number}, {"minItems", 3}, {"maxItems", 3}};
  scene_ch_ = server_.add_channel({"/platform/scene", "json", "microcobot.Scene", "jsonschema",
                                   schema({{"part_side_m", number},
                                           {"target_m", vec3},
                                           {"tolerance_m", number},
                                           {"max_opening_m", number},
                                           {"finger_width_m", number},
                                           {"workspace_min_m", vec3},
                                           {"workspace_max_m", vec3},
                                           {"max_speed_m_s", number}})});
  feedback_ch_ = server_.add_channel({"/console/feedback", "json", "microcobot.Feedback", "jsonschema",
                                      schema({{"contact_N", vec3}, {"grip_N", number}, {"rumble", number}})});
  server_.on_client_message([this](const server::ClientMessage& m) { on_message(m); });
  server_.on_disconnect([this](server::ClientId c) { on_disconnect(c); });
  json_.reserve(4096);
}

ConsoleServer::~ConsoleServer() { stop(); }

std::string ConsoleServer::url() const {
  std::string host = params_.server.address;
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
  server_.stop();
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
      } catch (const std::exception& e) {
        server_.broadcast_status(StatusLevel::kError, std::string("recording stopped: ") + e.what());
        recording_.reset();  // removes the temporary file; nothing half-written remains
        recording_name_.clear();
      }
    }
  }
  ticks_.add(s[kTick] * 1e-6);
  if (ticks_.count() >= 1000) {  // the loop's tick p99 over the last second
    tick_p99_us_.store(1e6 * ticks_.quantile_s(0.99));
    ticks_.reset();
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
      const ConsoleCommand c = parse_console_command(m.payload, live_.limits());
      if (m.client != controller) {
        server_.send_status(m.client, StatusLevel::kWarning, "control: take control first; command ignored",
                            "control");
        return;
      }
      if (!live_.push_command(c))
        server_.send_status(m.client, StatusLevel::kWarning,
                            "/console/command: the loop is busy; command dropped");
      return;
    }
    if (m.topic != "/console/action") {
      server_.send_status(m.client, StatusLevel::kError,
                          "unknown topic '" + std::string(m.topic.substr(0, 80)) +
                              "': the console publishes /console/command and /console/action");
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
    server_.send_status(m.client, StatusLevel::kError, e.what());
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
  char name[64];
  std::strftime(name, sizeof name, "recording-%Y%m%d-%H%M%S.mcap", &tm);
  auto w = std::make_unique<McapWriter>(params_.out_dir / name);
  const auto schema_id = w->add_schema(platform::kTelemetrySchemaName, "jsonschema",
                                       platform::telemetry_json_schema(live_.channel_count()));
  recording_channel_ = w->add_channel(schema_id, platform::kTelemetryTopic, "json");
  recording_ = std::move(w);
  recording_name_ = name;
}

void ConsoleServer::stop_recording() {
  std::unique_ptr<McapWriter> w;
  {
    std::lock_guard lock(recording_mutex_);
    w = std::move(recording_);
    recording_name_.clear();
  }
  if (w) w->close();  // summary, index, footer; then renamed to its name
}

std::string ConsoleServer::scene_json() const {
  const auto& c = live_.limits();
  return json{{"part_side_m", live_.part_side_m()},
              {"target_m", live_.target_m()},
              {"tolerance_m", live_.placement_tolerance_m()},
              {"max_opening_m", c.max_opening_m},
              {"finger_width_m", live_.finger_width_m()},
              {"workspace_min_m", c.min_m},
              {"workspace_max_m", c.max_m},
              {"max_speed_m_s", c.max_speed_m_s}}
      .dump();
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
            {"clients", server_.client_count()},
            {"recording", recording.empty() ? json(nullptr) : json(recording)},
            {"last_error", s.last_error}};
  return j.dump();
}

void ConsoleServer::status_thread() {
  const auto period = std::chrono::duration<double>(1.0 / params_.status_rate_Hz);
  auto next = std::chrono::steady_clock::now();
  int n = 0;
  while (!quit_.load()) {
    next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
    std::this_thread::sleep_until(next);
    const auto ns = static_cast<std::uint64_t>(std::llround(live_.status().t_s * 1e9));
    server_.publish(status_ch_, ns, status_json());
    if (n++ % static_cast<int>(std::max(1.0, params_.status_rate_Hz)) == 0)
      server_.publish(scene_ch_, ns, scene_json());
  }
}

}  // namespace mc::live

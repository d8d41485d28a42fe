#include "microcobot/live/console_server.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "microcobot/core/error.h"
#include "microcobot/live/camera_messages.h"
#include "microcobot/live/console_page.h"
#include "microcobot/live/console_task.h"
#include "microcobot/platform/telemetry_json.h"

namespace mc::live {
namespace {

using nlohmann::json;
using server::StatusLevel;

constexpr double kTelemetryRate_Hz = 1000.0;  // the platform's telemetry task (loop.telemetry_divisor)

const std::size_t kContactX = platform::telemetry_channel_index("contact_x_N");
const std::size_t kGrip = platform::telemetry_channel_index("grip_force_N");
const std::size_t kTick = platform::telemetry_channel_index("tick_us");
const std::size_t kTickCpu = platform::telemetry_channel_index("tick_cpu_us");

std::string schema(const json& properties) {
  return json{{"type", "object"}, {"properties", properties}}.dump();
}

// With only some properties always present (the others depend on the scene).
std::string schema(const json& properties, const std::vector<std::string>& required) {
  return json{{"type", "object"}, {"properties", properties}, {"required", required}}.dump();
}

EventLevel event_level(StatusLevel level) { return static_cast<EventLevel>(static_cast<int>(level)); }

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
      frames_(live.telemetry_schema(), live.params().platform.parallel_positioner_enabled()
                                           ? &live.params().platform.parallel_positioner.geometry
                                           : nullptr),
      rumble_(params_.rumble_crossover_Hz, kTelemetryRate_Hz, params_.rumble_full_scale_N) {
  if (live.params().platform.parallel_positioner_enabled())
    pose_goal_.emplace(live.params().platform.parallel_positioner.geometry);
  decimation_ =
      static_cast<std::size_t>(std::max(1.0, std::round(kTelemetryRate_Hz / params_.telemetry_rate_Hz)));
  ch_.telemetry = server_.add_channel({std::string(platform::kTelemetryTopic), "json",
                                       std::string(platform::kTelemetrySchemaName), "jsonschema",
                                       platform::telemetry_json_schema(live_.telemetry_schema())});
  const json number = {{"type", "number"}}, boolean = {{"type", "boolean"}}, text = {{"type", "string"}};
  ch_.status = server_.add_channel({"/platform/status", "json", "microcobot.Status", "jsonschema",
                                    schema({{"t_s", number},
                                            {"estopped", boolean},
                                            {"controlled", boolean},
                                            {"console_fresh", boolean},
                                            {"control", text},
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
                                            {"camera", {{"type", {"object", "null"}}}},
                                            {"demo_result", {{"type", {"object", "null"}}}},
                                            {"task", {{"type", {"object", "null"}}}},
                                            {"grip_vision", {{"type", {"object", "null"}}}}})});
  const json vec3 = {{"type", "array"}, {"items", number}, {"minItems", 3}, {"maxItems", 3}};
  // The optical-trap scene adds its beads; the pick-and-place keys are always there.
  const std::vector<std::string> scene_keys = {"kind",
                                               "part_side_m",
                                               "part_height_m",
                                               "hole_side_m",
                                               "hole_depth_m",
                                               "part_yaw_rad",
                                               "hole_yaw_rad",
                                               "theta_min_rad",
                                               "theta_max_rad",
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
                                               "demo_unavailable_reason",
                                               "neighbours",
                                               "optics"};
  ch_.scene =
      server_.add_channel({"/platform/scene", "json", "microcobot.Scene", "jsonschema",
                           schema({{"kind", text},
                                   {"part_side_m", number},
                                   {"part_height_m", number},
                                   {"hole_side_m", number},
                                   {"hole_depth_m", number},
                                   {"part_yaw_rad", number},
                                   {"hole_yaw_rad", number},
                                   {"theta_min_rad", number},
                                   {"theta_max_rad", number},
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
                                   {"obstacle_radius_m", number},
                                   {"camera", {{"type", {"object", "null"}}}},
                                   {"neighbours", {{"type", "array"}, {"items", {{"type", "object"}}}}},
                                   {"optics", {{"type", "object"}}}},
                                  scene_keys)});
  ch_.feedback = server_.add_channel(
      {"/console/feedback", "json", "microcobot.Feedback", "jsonschema",
       schema({{"t_s", number}, {"contact_N", vec3}, {"grip_N", number}, {"rumble", number}})});
  ch_.tf = server_.add_channel({std::string(kTransformsTopic), "json", "foxglove.FrameTransforms",
                                "jsonschema", RobotFrames::transforms_schema()});
  ch_.robot_scene = server_.add_channel({std::string(kRobotSceneTopic), "json", "foxglove.SceneUpdate",
                                         "jsonschema", RobotFrames::scene_update_schema()});
  if (live_.has_camera()) {
    // A slow viewer gets the newest image, not a queue of old ones (scene-to-screen latency).
    ch_.image = server_.add_channel({std::string(kCameraImageTopic), "cdr", "sensor_msgs/msg/CompressedImage",
                                     "ros2msg", std::string(compressed_image_schema()), true});
    ch_.preview =
        server_.add_channel({std::string(kCameraPreviewTopic), "cdr", "sensor_msgs/msg/CompressedImage",
                             "ros2msg", std::string(compressed_image_schema()), true});
    preview_ = std::make_unique<CameraPreview>();
    snapshot_ = std::make_unique<CameraSnapshot>();
    ch_.info = server_.add_channel({std::string(kCameraInfoTopic), "cdr", "sensor_msgs/msg/CameraInfo",
                                    "ros2msg", std::string(camera_info_schema())});
    ch_.camera_state = server_.add_channel({std::string(kCameraStateTopic), "json", "microcobot.CameraState",
                                            "jsonschema", camera_state_schema()});
    live_.set_frame_sink([this](const devices::CameraFrame& f, double t_s) { on_frame(f, t_s); });
  }
  server_.on_client_message([this](const server::ClientMessage& m) { on_message(m); });
  server_.on_disconnect([this](server::ClientId c) { on_disconnect(c); });
  if (!params_.out_dir.empty()) {
    // The recording keeps the channels as the clients see them (their schemas), at full rate.
    const auto recorded = [this](server::ChannelId id) {
      const auto spec = server_.channel(id).value();
      return RecordedSchema{spec.topic, spec.schema_name, spec.schema};
    };
    SessionRecordingParams rp;
    rp.out_dir = params_.out_dir;
    rp.csv = params_.record_csv;
    rp.telemetry = live_.telemetry_schema();
    if (live_.params().platform.parallel_positioner_enabled())
      rp.positioner_geometry = live_.params().platform.parallel_positioner.geometry;
    rp.status = recorded(ch_.status);
    rp.scene = recorded(ch_.scene);
    rp.feedback = recorded(ch_.feedback);
    rp.version = params_.version;
    rp.config_yaml = params_.config_yaml;
    rp.camera = live_.has_camera();
    rp.video = params_.record_video;
    if (rp.camera) rp.frame_rate_Hz = live_.camera_params().frame_rate_Hz();
    rp.h264 = params_.h264;
    rp.on_error = [this](const std::string& why) {
      server_.broadcast_status(StatusLevel::kError, "recording stopped: " + why);
    };
    recording_ = std::make_unique<SessionRecording>(std::move(rp));
    files_ = std::make_unique<RecordingFiles>(
        params_.out_dir, [this] { return recording_->name(); },
        [this](StatusLevel level, const std::string& message) {
          server_.broadcast_status(level, message, "report");
        },
        params_.recovered);
  }
  server_.on_http_get([this](std::string_view path) -> std::optional<server::HttpReply> {
    if (snapshot_)
      if (auto r = snapshot_->reply(path)) return r;
    if (files_) return files_->on_http(path);
    return std::nullopt;
  });
  server_.on_reject(
      [this](server::ClientId client, StatusLevel level, std::string_view id, std::string_view message) {
        note(event_level(level), "protocol", std::string(id) + ": " + std::string(message), client);
      });
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
  update_camera_demand();  // nobody looks yet: the camera forms frames once someone does
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
  if (files_) files_->join();
}

void ConsoleServer::on_sample(const platform::TelemetrySample& s, std::size_t count) {
  const std::span<const double> sample(s.data(), count);
  if (recording_) recording_->telemetry(s, count);  // every sample; encoded by its writer
  for (const SampleConsumer& c : every_sample_consumers_) c(s);
  ticks_.add(s[kTick] * 1e-6);
  ticks_cpu_.add(s[kTickCpu] * 1e-6);
  if (ticks_.count() >= 1000) {  // the loop's tick p99 over the last second
    tick_p99_us_.store(1e6 * ticks_.quantile_s(0.99));
    tick_cpu_p99_us_.store(1e6 * ticks_cpu_.quantile_s(0.99));
    ticks_.reset();
    ticks_cpu_.reset();
  }
  rumble_.add(s[kContactX], s[kContactX + 1], s[kContactX + 2]);
  if (countdown_ > 0) {
    --countdown_;
    return;
  }
  countdown_ = decimation_ - 1;
  const auto ns = static_cast<std::uint64_t>(std::llround(std::max(0.0, s[0]) * 1e9));
  json_.clear();
  platform::telemetry_to_json(live_.telemetry_schema(), sample, json_);
  server_.publish(ch_.telemetry, ns, json_);  // recorded at full rate above
  if (server_.subscriber_count(ch_.tf) > 0) {
    frames_.transforms_json(s, tf_json_);
    server_.publish(ch_.tf, ns, tf_json_);
  }
  for (const SampleConsumer& c : sample_consumers_) c(s);
  const double rumble = rumble_.take();
  auto finite = [](double v) { return std::isfinite(v) ? v : 0.0; };
  const json f = {{"t_s", s[0]},
                  {"contact_N", {finite(s[kContactX]), finite(s[kContactX + 1]), finite(s[kContactX + 2])}},
                  {"grip_N", finite(s[kGrip])},
                  {"rumble", rumble}};
  publish(ch_.feedback, RecordedTopic::kFeedback, s[0], f.dump());
}

void ConsoleServer::on_frame(const devices::CameraFrame& f, double t_s) {
  const RosTime stamp = ros_time(t_s);
  // A frame formed while nobody needed its JPEG carries none (the demand changes between frames):
  // it goes everywhere but the image channel and a JPEG recording.
  const bool has_jpeg = !f.jpeg.empty();
  if (has_jpeg) encode_compressed_image(f, stamp, image_cdr_);
  encode_camera_info(f, stamp, info_cdr_);
  const LiveStatus s = live_.status();
  // The grip force seen in this frame (the gauge ran on it before it reached here).
  const bool grip_of_frame = s.grip_vision && s.grip_vision->t_mid_s == f.t_mid_s;
  const std::string state = camera_state_json(f, live_.camera_params().frame_rate_Hz(), s.camera_dropped,
                                              live_.camera_params().calibration(f.objective),
                                              grip_of_frame ? &*s.grip_vision : nullptr);
  const auto ns = static_cast<std::uint64_t>(std::llround(std::max(0.0, t_s) * 1e9));
  if (has_jpeg) server_.publish(ch_.image, ns, image_cdr_);
  if (server_.subscriber_count(ch_.preview) > 0) {
    encode_compressed_image(preview_->encode(f.image, live_.camera_params().jpeg_quality), stamp,
                            preview_cdr_);
    server_.publish(ch_.preview, ns, preview_cdr_);
  }
  server_.publish(ch_.info, ns, info_cdr_);
  server_.publish(ch_.camera_state, ns, state);
  snapshot_->offer(f, state, t_s);
  if (recording_)
    recording_->published_frame(t_s, f, has_jpeg ? image_cdr_ : std::string(), info_cdr_, state);
  for (const FrameConsumer& c : frame_consumers_) c.on_frame(f, t_s);
}

void ConsoleServer::add_frame_consumer(FrameConsumer consumer) {
  if (started_) throw InvalidInput("console server: add frame consumers before start()");
  frame_consumers_.push_back(std::move(consumer));
}

void ConsoleServer::add_sample_consumer(SampleConsumer consumer) {
  if (started_) throw InvalidInput("console server: add sample consumers before start()");
  sample_consumers_.push_back(std::move(consumer));
}

void ConsoleServer::add_every_sample_consumer(SampleConsumer consumer) {
  if (started_) throw InvalidInput("console server: add sample consumers before start()");
  every_sample_consumers_.push_back(std::move(consumer));
}

void ConsoleServer::publish(server::ChannelId ch, RecordedTopic topic, double t_s,
                            const std::string& payload) {
  server_.publish(ch, static_cast<std::uint64_t>(std::llround(std::max(0.0, t_s) * 1e9)), payload);
  if (recording_) recording_->published(topic, t_s, payload);
}

void ConsoleServer::note(EventLevel level, std::string_view kind, const std::string& message,
                         server::ClientId client) {
  if (recording_) recording_->event(level, kind, message, client, live_.status().t_s);
}

std::string ConsoleServer::start_recording(std::optional<RecordedVideo> video) {
  if (!recording_) throw InvalidInput("recording is disabled: serve was started without --out");
  const double t_s = live_.status().t_s;
  const std::string was = recording_->name();
  const std::string name = recording_->start(t_s, scene_json(), video);
  recording_->robot_bodies(t_s, robot_bodies());  // the 3-D bodies from the start
  if (name != was)
    note(EventLevel::kInfo, "record_start",
         "recording to " + name + " (video " + std::string(recorded_video_name(recording_->video())) + ")");
  update_camera_demand();
  return name;
}

void ConsoleServer::stop_recording() {
  if (recording_) recording_->stop();  // summary, index, footer; then renamed to its name
}

SessionRecording::VideoStats ConsoleServer::recording_video_stats() const {
  return recording_ ? recording_->video_stats() : SessionRecording::VideoStats{};
}

void ConsoleServer::update_camera_demand() {
  if (!live_.has_camera()) return;
  // A recording that keeps the camera is a viewer of it.
  const bool recording = recording_ && recording_->video() != RecordedVideo::kOff;
  const bool watched = server_.subscriber_count(ch_.image) + server_.subscriber_count(ch_.preview) +
                           server_.subscriber_count(ch_.info) + server_.subscriber_count(ch_.camera_state) >
                       0;
  bool consumed = false;
  for (const FrameConsumer& c : frame_consumers_) consumed = consumed || c.wanted();
  live_.set_camera_wanted(recording || watched || consumed);
  // The JPEG is for the image channel, a JPEG recording and the consumers (the DDS image topic);
  // the preview, the camera's state, the vision, the snapshot and H.264 read the frame raw.
  const bool jpeg_recorded = recording_ && recording_->video() == RecordedVideo::kJpeg;
  live_.set_camera_jpeg_wanted(jpeg_recorded || consumed || server_.subscriber_count(ch_.image) > 0);
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
    const LiveStatus now_status = live_.status();
    live_.drain_command_latencies(latency_);
    live_.drain_link_costs(link_cost_);
    update_camera_demand();
    publish(ch_.status, RecordedTopic::kStatus, now_status.t_s, status_json());
    // The recording writes the bodies again only when they change (a restart, another scene).
    if (recording_) recording_->robot_bodies(now_status.t_s, robot_bodies());
    if (n % static_cast<int>(std::max(1.0, params_.status_rate_Hz)) == 0) {
      publish(ch_.scene, RecordedTopic::kScene, now_status.t_s, scene_json());
      if (server_.subscriber_count(ch_.robot_scene) > 0)
        server_.publish(ch_.robot_scene,
                        static_cast<std::uint64_t>(std::llround(std::max(0.0, now_status.t_s) * 1e9)),
                        robot_scene_json(now_status.t_s));
    }
    ++n;
    note_changes(now_status);
  }
}

}  // namespace mc::live

#include "microcobot/live/session_recording.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <span>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "microcobot/core/csv_stream_writer.h"
#include "microcobot/core/error.h"
#include "microcobot/core/mcap_writer.h"
#include "microcobot/live/camera_messages.h"
#include "microcobot/platform/telemetry_json.h"

namespace mc::live {
namespace {

using nlohmann::json;

constexpr std::size_t index(RecordedTopic t) { return static_cast<std::size_t>(t); }

std::string object_schema(const json& properties) {
  return json{{"type", "object"}, {"properties", properties}}.dump();
}

// What a client sent, as received: the message itself when it is JSON, else its text (a
// refused, malformed message is worth keeping too).
std::string received_json(std::uint64_t client, double t_s, std::string_view payload) {
  json message = json::parse(payload, nullptr, /*allow_exceptions=*/false);
  if (message.is_discarded()) message = std::string(payload.substr(0, 4096));
  return json{{"t_s", t_s}, {"client", client}, {"message", std::move(message)}}.dump(
      -1, ' ', false, json::error_handler_t::replace);
}

std::string utc_iso(std::int64_t ns) {
  const std::time_t s = static_cast<std::time_t>(ns / 1000000000);
  std::tm tm{};
  gmtime_r(&s, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &tm);
  return fmt::format("{}.{:03d}Z", text, static_cast<int>((ns / 1000000) % 1000));
}

}  // namespace

void SessionRecordingParams::validate() const {
  require(!telemetry.empty(), "telemetry", "needs the telemetry's channels");
  for (const RecordedSchema* s : {&status, &scene, &feedback})
    require(!s->topic.empty() && !s->schema.empty(), "recorded channels", "need a topic and a schema");
  require(std::isfinite(frame_rate_Hz) && frame_rate_Hz > 0.0, "frame_rate_Hz", "must be > 0", frame_rate_Hz);
  try {
    h264.validate();
  } catch (const InvalidParams& e) {
    throw e.nested_in("h264");
  }
}

bool SessionRecording::is_stem(std::string_view stem) {
  constexpr std::string_view prefix = "recording-";
  if (stem.size() <= prefix.size() || stem.size() > 64 || stem.substr(0, prefix.size()) != prefix)
    return false;
  return stem.find_first_not_of("0123456789-", prefix.size()) == std::string_view::npos;
}

SessionRecording::SessionRecording(SessionRecordingParams params) : params_(std::move(params)) {
  params_.validate();
  if (RobotFrames::fits(params_.telemetry))
    frames_.emplace(params_.telemetry, params_.positioner_geometry ? &*params_.positioner_geometry : nullptr);
}

SessionRecording::~SessionRecording() {
  {
    std::lock_guard lock(mutex_);
    active_ = false;
    stopping_ = true;
    error_ = "abandoned";
  }
  wake_.notify_all();
  if (writer_.joinable()) writer_.join();
  // mcap_, csv_ destroyed unclosed: their temporary files are removed.
}

std::string SessionRecording::name() const {
  std::lock_guard lock(mutex_);
  return active_ ? name_ : std::string();
}

RecordedVideo SessionRecording::video() const {
  std::lock_guard lock(mutex_);
  return active_ ? video_ : RecordedVideo::kOff;
}

SessionRecording::VideoStats SessionRecording::video_stats() const {
  std::lock_guard lock(mutex_);
  return video_stats_;
}

std::string SessionRecording::start(double t_s, const std::string& scene_json,
                                    std::optional<RecordedVideo> video_asked) {
  std::lock_guard control(control_mutex_);
  {
    std::lock_guard lock(mutex_);
    if (active_) return name_;
  }
  if (writer_.joinable()) writer_.join();  // a writer that gave up (its error was reported)
  mcap_.reset();
  csv_.reset();
  const RecordedVideo video = params_.camera ? video_asked.value_or(params_.video) : RecordedVideo::kOff;
  // The encoder first: a libavcodec without libx264 refuses the recording before any file exists.
  encoder_ = video == RecordedVideo::kH264
                 ? std::make_unique<H264Encoder>(params_.h264, params_.frame_rate_Hz)
                 : nullptr;

  const auto wall = std::chrono::system_clock::now();
  const std::int64_t wall_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(wall.time_since_epoch()).count();
  const std::time_t now = std::chrono::system_clock::to_time_t(wall);
  std::tm tm{};
  localtime_r(&now, &tm);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "recording-%Y%m%d-%H%M%S", &tm);
  std::string stem = stamp;
  const auto taken = [&](const std::string& s) {
    return std::filesystem::exists(params_.out_dir / (s + ".mcap")) ||
           std::filesystem::exists(params_.out_dir / (s + ".csv"));
  };
  for (int i = 2; taken(stem) && i < 1000; ++i) stem = std::string(stamp) + "-" + std::to_string(i);

  // The time base: wall clock at start minus loop time at start.
  const std::int64_t offset_ns = wall_ns - std::llround(t_s * 1e9);
  auto w = std::make_unique<McapWriter>(
      params_.out_dir / (stem + ".mcap"),
      video != RecordedVideo::kOff ? kCameraChunkBytes : McapWriter::kDefaultChunkBytes,
      McapCompression{true, kZstdLevel});
  w->set_chunk_max_span_ns(kChunkSpan_ns);
  const auto add = [&](RecordedTopic t, const std::string& topic, const std::string& schema_name,
                       const std::string& schema) {
    channel_[index(t)] = w->add_channel(w->add_schema(schema_name, "jsonschema", schema), topic, "json");
  };
  add(RecordedTopic::kTelemetry, std::string(platform::kTelemetryTopic),
      std::string(platform::kTelemetrySchemaName), platform::telemetry_json_schema(params_.telemetry));
  add(RecordedTopic::kStatus, params_.status.topic, params_.status.schema_name, params_.status.schema);
  add(RecordedTopic::kScene, params_.scene.topic, params_.scene.schema_name, params_.scene.schema);
  add(RecordedTopic::kFeedback, params_.feedback.topic, params_.feedback.schema_name,
      params_.feedback.schema);
  const json number = {{"type", "number"}}, text = {{"type", "string"}};
  const json client = {{"type", "number"}, {"description", "the server's id of the client (1, 2, ...)"}};
  const json received = {{"t_s", number}, {"client", client}, {"message", {{"description", "as received"}}}};
  add(RecordedTopic::kCommand, "/console/command", "microcobot.ReceivedCommand", object_schema(received));
  add(RecordedTopic::kAction, "/console/action", "microcobot.ReceivedAction", object_schema(received));
  add(RecordedTopic::kEvents, "/events", "microcobot.Event",
      object_schema({{"t_s", number},
                     {"level", {{"type", "number"}, {"description", "0 info, 1 warning, 2 error"}}},
                     {"kind", text},
                     {"message", text},
                     {"client", {{"type", {"number", "null"}}}}}));
  if (frames_) {
    add(RecordedTopic::kTransforms, std::string(kTransformsTopic), "foxglove.FrameTransforms",
        RobotFrames::transforms_schema());
    add(RecordedTopic::kRobotScene, std::string(kRobotSceneTopic), "foxglove.SceneUpdate",
        RobotFrames::scene_update_schema());
  }
  if (video == RecordedVideo::kH264) {
    channel_[index(RecordedTopic::kCameraImage)] =
        w->add_channel(w->add_schema("foxglove.CompressedVideo", "jsonschema", compressed_video_schema()),
                       std::string(kCameraVideoTopic), "json");
  } else if (video == RecordedVideo::kJpeg) {
    channel_[index(RecordedTopic::kCameraImage)] =
        w->add_channel(w->add_schema("sensor_msgs/msg/CompressedImage", "ros2msg", compressed_image_schema()),
                       std::string(kCameraImageTopic), "cdr");
  }
  if (video != RecordedVideo::kOff) {
    channel_[index(RecordedTopic::kCameraInfo)] =
        w->add_channel(w->add_schema("sensor_msgs/msg/CameraInfo", "ros2msg", camera_info_schema()),
                       std::string(kCameraInfoTopic), "cdr");
    add(RecordedTopic::kCameraState, std::string(kCameraStateTopic), "microcobot.CameraState",
        camera_state_schema());
  }

  const std::string started = utc_iso(wall_ns);
  w->add_metadata("microcobot", {{"version", params_.version},
                                 {"recording", stem + ".mcap"},
                                 {"started_utc", started},
                                 {"started_t_s", fmt::format("{:.6f}", t_s)},
                                 {"log_time", "t_s * 1e9 + time_offset_ns (ns since 1970-01-01 UTC)"},
                                 {"time_offset_ns", std::to_string(offset_ns)},
                                 {"telemetry_rate_Hz", "1000"}});
  std::vector<std::pair<std::string, std::string>> scene;
  const json sj = json::parse(scene_json, nullptr, false);
  if (sj.is_object())
    for (const auto& [k, v] : sj.items())
      scene.emplace_back(k, v.is_string() ? v.get<std::string>() : v.dump());
  w->add_metadata("scene", scene);
  w->add_metadata("configuration", {{"yaml", params_.config_yaml}});
  std::vector<std::pair<std::string, std::string>> video_entries = {
      {"format", std::string(recorded_video_name(video))}};
  if (video == RecordedVideo::kH264) {
    const H264Params& h = params_.h264;
    video_entries.insert(video_entries.end(),
                         {{"topic", std::string(kCameraVideoTopic)},
                          {"encoder", "libx264 (libavcodec)"},
                          {"preset", h.preset},
                          {"tune", h.tune},
                          {"crf", fmt::format("{:g}", h.crf)},
                          {"keyframe_interval_s", fmt::format("{:g}", h.keyframe_interval_s)},
                          {"b_frames", "0"},
                          {"pixel_format", "yuv420p full range (grey: chroma 128)"},
                          {"frame_rate_Hz", fmt::format("{:g}", params_.frame_rate_Hz)}});
  } else if (video == RecordedVideo::kJpeg) {
    video_entries.emplace_back("topic", std::string(kCameraImageTopic));
  }
  w->add_metadata("video", video_entries);
  w->add_attachment("configuration.yaml", "application/yaml", params_.config_yaml,
                    static_cast<std::uint64_t>(wall_ns), static_cast<std::uint64_t>(wall_ns));

  std::unique_ptr<CsvStreamWriter> csv;
  if (params_.csv) {
    csv = std::make_unique<CsvStreamWriter>(params_.out_dir / (stem + ".csv"), params_.telemetry.names());
  }
  mcap_ = std::move(w);
  csv_ = std::move(csv);
  {
    std::lock_guard lock(mutex_);
    active_ = true;
    stopping_ = false;
    name_ = stem + ".mcap";
    queue_.clear();
    queued_bytes_ = 0;
    dropped_ = 0;
    offset_ns_ = offset_ns;
    last_ns_.fill(0);
    error_.clear();
    video_ = video;
    video_stats_ = {};
  }
  last_keyframe_t_s_ = -1.0;
  next_tf_t_s_.reset();
  scene_written_.reset();
  writer_ = std::thread([this] { writer_thread(); });
  return stem + ".mcap";
}

void SessionRecording::stop() {
  std::lock_guard control(control_mutex_);
  std::uint64_t dropped = 0;
  double t_s = 0.0;
  {
    std::lock_guard lock(mutex_);
    if (!active_ && !writer_.joinable()) return;
    dropped = dropped_;
    if (!queue_.empty()) t_s = queue_.back().t_s;
  }
  if (dropped > 0)
    event(EventLevel::kWarning, "dropped",
          fmt::format("{} message(s) dropped: the writer fell {} MB behind", dropped, kMaxQueuedBytes >> 20),
          0, t_s);
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;  // the writer empties the queue, then closes the files
  }
  wake_.notify_all();
  if (writer_.joinable()) writer_.join();
  std::string error;
  {
    std::lock_guard lock(mutex_);
    active_ = false;
    name_.clear();
    error = error_;
  }
  std::unique_ptr<McapWriter> mcap = std::move(mcap_);
  std::unique_ptr<CsvStreamWriter> csv = std::move(csv_);
  if (!error.empty() || !mcap) return;  // already abandoned and reported
  mcap->close();                        // summary, index, footer; then renamed to its name
  if (csv) csv->close();
}

void SessionRecording::push(std::span<Item> items) {
  std::size_t bytes = 0;
  for (const Item& item : items) bytes += sizeof(Item) + item.payload.size();
  {
    std::lock_guard lock(mutex_);
    if (!active_ || stopping_) return;
    if (queued_bytes_ + bytes > kMaxQueuedBytes) {
      dropped_ += items.size();
      return;
    }
    for (Item& item : items) {
      std::uint64_t& last = last_ns_[index(item.topic)];
      const std::int64_t ns = std::llround(item.t_s * 1e9) + offset_ns_;
      item.log_ns = std::max(last, static_cast<std::uint64_t>(std::max<std::int64_t>(ns, 0)));
      last = item.log_ns;
      queue_.push_back(std::move(item));
    }
    queued_bytes_ += bytes;
  }
  wake_.notify_one();
}

void SessionRecording::telemetry(const platform::TelemetrySample& s, std::size_t count) {
  Item item{RecordedTopic::kTelemetry, 0, s[0], {}, s, std::min(count, params_.telemetry.size()), {}, {}};
  push(std::move(item));
}

void SessionRecording::published(RecordedTopic topic, double t_s, std::string_view payload) {
  push(Item{topic, 0, t_s, std::string(payload), {}, 0, {}, {}});
}

void SessionRecording::published_frame(double t_s, const devices::CameraFrame& frame, std::string_view image,
                                       std::string_view info, std::string_view state) {
  const RecordedVideo video = this->video();
  if (video == RecordedVideo::kOff) return;
  Item picture{RecordedTopic::kCameraImage, 0, t_s, {}, {}, 0, {}, {}};
  if (video == RecordedVideo::kH264) {
    try {
      const VideoImage v = to_video_image(frame.image, picture.payload);  // 8-bit: half a 12-bit frame
      picture.shape = {v.width, v.height, v.channels};
    } catch (const InvalidInput& e) {
      event(EventLevel::kWarning, "video", std::string("frame not recorded: ") + e.what(), 0, t_s);
      return;
    }
  } else if (image.empty()) {
    return;  // formed before the recording asked for JPEGs: the next frames carry one
  } else {
    picture.payload = std::string(image);
  }
  std::array<Item, 3> items{std::move(picture),
                            Item{RecordedTopic::kCameraInfo, 0, t_s, std::string(info), {}, 0, {}, {}},
                            Item{RecordedTopic::kCameraState, 0, t_s, std::string(state), {}, 0, {}, {}}};
  push(items);
}

void SessionRecording::robot_bodies(double t_s, const RobotBodies& bodies) {
  if (!frames_) return;
  Item item{RecordedTopic::kRobotScene, 0, t_s, {}, {}, 0, {}, bodies};
  push(std::move(item));
}

void SessionRecording::received(RecordedTopic topic, std::uint64_t client, double t_s,
                                std::string_view payload) {
  push(Item{topic, 0, t_s, received_json(client, t_s, payload), {}, 0, {}, {}});
}

void SessionRecording::event(EventLevel level, std::string_view kind, std::string_view message,
                             std::uint64_t client, double t_s) {
  const json j = {{"t_s", t_s},
                  {"level", static_cast<int>(level)},
                  {"kind", kind},
                  {"message", message},
                  {"client", client ? json(client) : json(nullptr)}};
  push(Item{
      RecordedTopic::kEvents, 0, t_s, j.dump(-1, ' ', false, json::error_handler_t::replace), {}, 0, {}, {}});
}

void SessionRecording::writer_thread() {
  std::vector<Item> batch;
  std::string json_text;
  while (true) {
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return !queue_.empty() || stopping_; });
      if (queue_.empty()) break;  // stopping, and everything queued is written
      batch.swap(queue_);
      queued_bytes_ = 0;
    }
    try {
      for (const Item& item : batch) {
        const std::uint16_t channel = channel_[index(item.topic)];
        if (item.topic == RecordedTopic::kCameraImage && encoder_) {
          write_video(item);
        } else if (item.topic == RecordedTopic::kTelemetry) {
          const std::span<const double> sample(item.sample.data(), item.count);
          json_text.clear();
          platform::telemetry_to_json(params_.telemetry, sample, json_text);
          mcap_->write(channel, item.log_ns, item.log_ns, json_text);
          if (csv_) csv_->append(sample);
          write_transforms(item);
        } else if (item.topic == RecordedTopic::kRobotScene) {
          if (scene_written_ == item.bodies) continue;  // unchanged: the viewer keeps what it has
          mcap_->write(channel, item.log_ns, item.log_ns, frames_->scene_update_json(item.bodies, item.t_s));
          scene_written_ = item.bodies;
        } else {
          mcap_->write(channel, item.log_ns, item.log_ns, item.payload);
        }
      }
    } catch (const std::exception& e) {
      abandon(e.what());
      return;
    }
    batch.clear();
  }
  // The frames still in the encoder's lookahead, before the files close.
  if (!encoder_) return;
  try {
    encoder_->flush([this](const H264Packet& p) { write_packet(p); });
  } catch (const std::exception& e) {
    abandon(e.what());
  }
}

void SessionRecording::write_transforms(const Item& item) {
  if (!frames_) return;
  // The samples on a grid kTransformsRate_Hz apart, within half a telemetry period (the loop's
  // times are not exact multiples): a lost sample's next one stands in for it and the grid goes
  // on; a time far off the grid (a rebuilt platform's loop) starts a new one.
  constexpr double period_s = 1.0 / kTransformsRate_Hz, slack_s = 0.5e-3;
  const double t = item.t_s;
  if (next_tf_t_s_ && t < *next_tf_t_s_ - slack_s && t > *next_tf_t_s_ - 1.5 * period_s) return;
  frames_->transforms_json(item.sample, tf_json_);
  // At the sample's own log time: a reader finds the telemetry the frames came from.
  mcap_->write(channel_[index(RecordedTopic::kTransforms)], item.log_ns, item.log_ns, tf_json_);
  const bool on_grid = next_tf_t_s_ && t >= *next_tf_t_s_ - slack_s && t < *next_tf_t_s_ + period_s - slack_s;
  next_tf_t_s_ = (on_grid ? *next_tf_t_s_ : t) + period_s;
}

void SessionRecording::write_video(const Item& item) {
  const VideoImage image{
      item.shape.width, item.shape.height, item.shape.channels,
      std::span(reinterpret_cast<const std::uint8_t*>(item.payload.data()), item.payload.size())};
  {
    std::lock_guard lock(mutex_);
    ++video_stats_.frames;
    video_stats_.thread = std::this_thread::get_id();
  }
  encoder_->encode(image, item.t_s, item.log_ns, [this](const H264Packet& p) { write_packet(p); });
}

void SessionRecording::write_packet(const H264Packet& p) {
  encode_compressed_video(p.annexb, ros_time(p.t_s), video_message_);
  mcap_->write(channel_[index(RecordedTopic::kCameraImage)], p.tag, p.tag, video_message_);
  std::lock_guard lock(mutex_);
  VideoStats& s = video_stats_;
  ++s.packets;
  s.bytes += p.annexb.size();
  if (p.keyframe) {
    ++s.keyframes;
    if (last_keyframe_t_s_ >= 0.0)
      s.longest_keyframe_gap_s = std::max(s.longest_keyframe_gap_s, p.t_s - last_keyframe_t_s_);
    last_keyframe_t_s_ = p.t_s;
  }
}

void SessionRecording::abandon(const std::string& why) {
  // A failed write (a full disk): the MCAP file cut back to its last chunk written through and
  // closed there, a readable recording up to that half second; when even that cannot be written
  // its temporary stays, and the next serve recovers its whole chunks. The CSV file is removed.
  std::string kept;
  if (mcap_) {
    const std::string file = mcap_->path().filename().string();
    try {
      const std::uint64_t n = mcap_->close_at_last_chunk();
      kept = fmt::format("; {} kept up to its last half second ({} messages)", file, n);
    } catch (const std::exception&) {
      kept = "; " + file + " left unfinished: serve recovers it at its next start";
    }
  }
  mcap_.reset();
  csv_.reset();
  {
    std::lock_guard lock(mutex_);
    active_ = false;
    error_ = why + kept;
    queue_.clear();
    queued_bytes_ = 0;
    name_.clear();
  }
  if (params_.on_error) params_.on_error(why + kept);
}

}  // namespace mc::live

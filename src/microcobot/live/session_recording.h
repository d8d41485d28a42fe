#pragma once
/// @file
/// The recording of a live session (`serve`, docs/console.md "Recordings"): one MCAP file that
/// holds what the server saw and did, so that a recording alone tells what happened:
///
///   /platform/telemetry  every sample of the loop's 1 kHz telemetry (the clients get 60 Hz)
///   /platform/status, /platform/scene, /console/feedback   what the server published
///   /console/command, /console/action   what the clients sent: `{"t_s", "client", "message"}`
///   /events   state changes and errors: `{"t_s", "level", "kind", "message", "client"}`
///   /tf (foxglove.FrameTransforms) the robot's frames (live/robot_frames.h) of the telemetry
///   samples kTransformsRate_Hz apart, and /robot/scene (foxglove.SceneUpdate) its bodies at the
///   start and whenever they change: Foxglove's 3D panel replays the robot from the file. Both
///   are computed by the writer from what the recording holds, with the server's schemas.
///   /camera/video (foxglove.CompressedVideo, H.264) or /camera/image/compressed (CDR JPEG), with
///   /camera/camera_info (CDR) and /camera/state (JSON): every frame of the camera, when the
///   platform has one and the recording keeps it (live/recorded_video.h, live/camera_messages.h)
///   Metadata "microcobot" (version, start, the time base), "scene", "configuration" (YAML),
///   "video" (the camera's format and, for H.264, the encoder's settings), and the configuration
///   again as the attachment `configuration.yaml`.
///
/// Log times are on the wall clock (UTC, ns since the epoch), as viewers expect: the loop time
/// `t_s` (kept in every message) plus the offset wall-clock-at-start minus loop-time-at-start,
/// captured once, so the 1 kHz stream stays evenly spaced and monotonic whatever the wall
/// clock does later (NTP steps). Each channel's log times never decrease (an event stamped by
/// a thread that lost a race is stamped with the latest time of its channel).
///
/// Threads: the callers (drain thread, server I/O thread, status thread, camera thread) only
/// append to a queue under a short lock; a writer thread of the recording's own encodes the
/// telemetry as JSON and the camera's frames as H.264, compresses the chunks (zstd,
/// core/mcap_writer.h) and writes, so neither the loop, the drain nor the camera ever waits on a
/// disk or an encoder. The queue is bounded (kMaxQueuedBytes): beyond it messages are dropped and
/// counted in an event.
///
/// Files appear only when complete (temporary name, renamed at stop(): core/staged_file.h);
/// a failed write abandons the recording and leaves nothing under its name.

#include <array>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "microcobot/devices/camera_frame.h"
#include "microcobot/live/h264_encoder.h"
#include "microcobot/live/recorded_video.h"
#include "microcobot/live/robot_frames.h"
#include "microcobot/platform/platform.h"

namespace mc {
class CsvStreamWriter;
class McapWriter;
}  // namespace mc

namespace mc::live {

/// The channels of a recording, in the order their Channel records are written.
enum class RecordedTopic : std::uint8_t {
  kTelemetry,
  kStatus,
  kScene,
  kFeedback,
  kCommand,
  kAction,
  kEvents,
  kTransforms,   ///< /tf, written by the writer from the telemetry (never pushed)
  kRobotScene,   ///< /robot/scene: pushed as its bodies, written when they change
  kCameraImage,  ///< the frame: its JPEG message, or its samples for the H.264 encoder
  kCameraInfo,
  kCameraState,
  kCount
};

/// A JSON channel's schema, as the server advertises it.
struct RecordedSchema {
  std::string topic;
  std::string schema_name;
  std::string schema;  ///< JSON Schema text
};

/// An event's level, as the Foxglove status levels: 0 info, 1 warning, 2 error.
enum class EventLevel : std::uint8_t { kInfo = 0, kWarning = 1, kError = 2 };

struct SessionRecordingParams {
  std::filesystem::path out_dir;        ///< where recordings go
  bool csv = false;                     ///< also the telemetry as <stem>.csv (`serve --record-csv`)
  platform::TelemetrySchema telemetry;  ///< the telemetry's channels (LivePlatform::telemetry_schema())
  /// The parallel positioner's geometry (`positioner: parallel`): its base, legs and platform in
  /// the recorded /tf and /robot/scene, as the live channels have them.
  std::optional<motion::ParallelGeometryParams> positioner_geometry;
  /// /platform/status, /platform/scene, /console/feedback as the server advertises them.
  RecordedSchema status, scene, feedback;
  std::string version;      ///< the program's, e.g. "microcobot 0.1.0"
  std::string config_yaml;  ///< the platform configuration (`run --print-config`'s keys)
  /// The platform has a camera: recordings may keep its frames (chunks then hold several frames:
  /// kCameraChunkBytes).
  bool camera = false;
  /// How recordings keep the camera unless start() says otherwise (`serve --record-video`).
  RecordedVideo video = RecordedVideo::kH264;
  double frame_rate_Hz = 30.0;  ///< the camera's (the H.264 stream's time base)
  H264Params h264;              ///< the encoder's settings
  /// Called on the writer thread when a write fails and the recording is abandoned.
  std::function<void(const std::string& why)> on_error;
  void validate() const;
};

class SessionRecording {
 public:
  /// Beyond this many bytes waiting for the writer, messages are dropped (and counted).
  static constexpr std::size_t kMaxQueuedBytes = std::size_t{64} << 20;
  /// The zstd level of the chunks. A 1 MiB chunk of a live recording (`zstd -b1e3` on it, the
  /// 2-core machine): level 1 11.80 times smaller at 993 MB/s (about 1 ms), level 3 11.85 times
  /// at 232 MB/s: 1 gives the size for a quarter of the time.
  static constexpr int kZstdLevel = 1;
  /// Chunks of a recording with images: several JPEG frames each (a 1280x1024 frame is a few
  /// hundred kB), so that a chunk is never a single frame.
  static constexpr std::size_t kCameraChunkBytes = std::size_t{8} << 20;
  /// A chunk is closed and written through to the operating system every half second of
  /// messages: a crash (kill -9) loses the open chunk and what waits in the writer's queue, under
  /// a second (`serve` recovers the rest at start). Not synced to the disk: a power cut may also
  /// lose what the system had not written yet.
  static constexpr std::uint64_t kChunkSpan_ns = 500'000'000;
  /// The rate of /tf in a recording: one telemetry sample's frames every 10 ms. Every sample's
  /// (1 kHz) would add half to nearly all of the file again for a replay a viewer draws at its
  /// screen's rate (docs/console.md, "Recordings", Size: measured).
  static constexpr double kTransformsRate_Hz = 100.0;

  explicit SessionRecording(SessionRecordingParams params);
  /// An unstopped recording is abandoned (its temporary files removed).
  ~SessionRecording();
  SessionRecording(const SessionRecording&) = delete;
  SessionRecording& operator=(const SessionRecording&) = delete;

  /// Opens recording-YYYYmmdd-HHMMSS.mcap (and .csv) in out_dir, writes the metadata and starts
  /// the writer. `t_s` is the loop time now (the time base), `scene_json` the scene, `video` how
  /// this recording keeps the camera (unset: params' video). Returns the MCAP file's name; the
  /// same when already recording (its video unchanged). Throws InvalidInput when a file cannot be
  /// created, ComputationFailed when H.264 is asked and libavcodec cannot encode it.
  std::string start(double t_s, const std::string& scene_json, std::optional<RecordedVideo> video = {});
  /// Writes what is queued, closes and renames the files. Throws InvalidInput when the last
  /// writes fail (nothing then remains). Idempotent.
  void stop();
  /// The MCAP file being written ("" when not recording).
  std::string name() const;
  /// How the current recording keeps the camera (kOff when not recording or without a camera):
  /// whether it wants the camera's frames.
  RecordedVideo video() const;

  /// What the H.264 encoder of the last recording did. Complete after stop().
  struct VideoStats {
    std::uint64_t frames = 0;     ///< frames given to the encoder
    std::uint64_t packets = 0;    ///< access units written (one a frame)
    std::uint64_t keyframes = 0;  ///< of them, IDR pictures
    std::uint64_t bytes = 0;      ///< H.264 bytes (before base64)
    double longest_keyframe_gap_s = 0.0;
    std::thread::id thread;  ///< the one that encoded (the writer)
  };
  VideoStats video_stats() const;

  /// A telemetry sample (drain thread): no allocation unless the queue grows.
  void telemetry(const platform::TelemetrySample& s, std::size_t count);
  /// A message the server published (status, scene, feedback): its payload as sent.
  void published(RecordedTopic topic, double t_s, std::string_view payload);
  /// A camera frame's three messages (image, camera info, state), recorded together or not at
  /// all: a stop between them never leaves a frame without its info or state. `image` is the
  /// frame's JPEG message (kept with jpeg; empty for a frame formed without its JPEG, which is then
  /// not recorded); with h264 the frame's samples are copied (8-bit) for the writer to encode. Camera thread:
  /// never waits for the encoder.
  void published_frame(double t_s, const devices::CameraFrame& frame, std::string_view image,
                       std::string_view info, std::string_view state);
  /// The robot's bodies now (any thread; cheap: the writer compares them with the last it wrote
  /// and writes /robot/scene only at the first and when they change). Nothing without the
  /// stage's channels in the telemetry (RobotFrames::fits).
  void robot_bodies(double t_s, const RobotBodies& bodies);
  /// A message a client sent on /console/command or /console/action, accepted or not.
  void received(RecordedTopic topic, std::uint64_t client, double t_s, std::string_view payload);
  /// An event (client 0: none).
  void event(EventLevel level, std::string_view kind, std::string_view message, std::uint64_t client,
             double t_s);

  /// Whether `stem` is a recording's: "recording-" then digits and dashes (what start() names),
  /// so that a request can name nothing else (no path, no hidden or temporary file).
  static bool is_stem(std::string_view stem);

 private:
  struct Item {
    RecordedTopic topic;
    std::uint64_t log_ns = 0;  // stamped by push()
    double t_s = 0.0;
    std::string payload;  // empty for telemetry: encoded by the writer; 8-bit samples of a frame to encode
    platform::TelemetrySample sample;
    std::size_t count = 0;
    struct Shape {
      int width = 0, height = 0, channels = 0;
    } shape;             // a frame to encode
    RobotBodies bodies;  // the scene's
  };
  void push(Item&& item) { push(std::span<Item>(&item, 1)); }
  void push(std::span<Item> items);  // all or none
  void writer_thread();
  void write_transforms(const Item& telemetry);
  void write_video(const Item& item);
  void write_packet(const H264Packet& packet);
  void abandon(const std::string& why);

  SessionRecordingParams params_;
  std::optional<RobotFrames> frames_;  // when the telemetry has the stage's channels
  std::mutex control_mutex_;           // start/stop

  mutable std::mutex mutex_;  // the queue and the state below
  std::condition_variable wake_;
  bool active_ = false, stopping_ = false;
  std::string name_;
  std::vector<Item> queue_;
  std::size_t queued_bytes_ = 0;
  std::uint64_t dropped_ = 0;
  std::int64_t offset_ns_ = 0;  // log time = t_s * 1e9 + offset_ns_
  std::array<std::uint64_t, static_cast<std::size_t>(RecordedTopic::kCount)> last_ns_{};
  RecordedVideo video_ = RecordedVideo::kOff;
  VideoStats video_stats_;

  // Writer thread (and start/stop while it is not running).
  std::thread writer_;
  std::unique_ptr<McapWriter> mcap_;
  std::unique_ptr<CsvStreamWriter> csv_;
  std::unique_ptr<H264Encoder> encoder_;  // with h264
  std::string video_message_;
  double last_keyframe_t_s_ = -1.0;
  std::optional<double> next_tf_t_s_;         // the telemetry time of the next /tf
  std::optional<RobotBodies> scene_written_;  // the bodies of the last /robot/scene written
  std::string tf_json_;
  std::array<std::uint16_t, static_cast<std::size_t>(RecordedTopic::kCount)> channel_{};
  std::string error_;  // why the writer gave up
};

}  // namespace mc::live

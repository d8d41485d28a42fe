#pragma once
/// @file
/// The live platform served to its operators (`microcobot serve`): the console page
/// over HTTP and the platform over the Foxglove WebSocket protocol (docs/console.md).
///
///   /platform/telemetry  60 Hz   the loop's telemetry (its TelemetrySchema), JSON
///   /platform/status      5 Hz   e-stop, control, watchdog, lifecycles, tick p99, recording
///   /platform/scene       1 Hz   geometry and limits the microscope view needs
///   /console/feedback    60 Hz   contact and grip forces, the vibrotactile channel
///   /tf                  60 Hz   the frames of the tool, gripper, fingers and part (and of the
///                                parallel positioner's platform, base, carriages and legs),
///                                foxglove.FrameTransforms (live/robot_frames.h)
///   /robot/scene          1 Hz   the fingers and the part as boxes in their frames (and the
///                                positioner's bodies), foxglove.SceneUpdate: Foxglove's 3D panel
///                                and the console's positioner view draw the platform
///   /camera/image/compressed     every camera frame, sensor_msgs/msg/CompressedImage (CDR, JPEG)
///   /camera/preview/compressed   the same frames binned to the console's 640 px panel
///                                (live/camera_preview.h), encoded only while someone watches
///   /camera/camera_info          every frame, sensor_msgs/msg/CameraInfo (CDR)
///   /camera/state                every frame, objective, focus, exposure, gain, scale (JSON)
///   client /console/command      the controlling client's command (~30 Hz heartbeat)
///   client /console/action       estop, reset, take/release control, demo, restart, record
///
/// HTTP: `/` the console; `/recordings...` the recordings in --out, their downloads and reports
/// (live/recording_files.h); `/camera/snapshot.tiff|.png` the latest full frame, lossless
/// (live/camera_snapshot.h). A recording (live/session_recording.h) holds every channel above at
/// full rate (the preview excepted: it holds the full frames; /tf at 100 Hz), what the clients sent, the
/// events (control, e-stop, demo, refusals, errors) and the configuration.
///
/// One client controls at a time; the others observe until they take control. Any client may
/// press the e-stop. Every message is parsed, checked and clamped (console_command.h) before it
/// reaches the loop, through the live platform's single-producer ring (the server runs one I/O
/// thread: the one producer). Telemetry leaves the loop through the platform's ring and is
/// encoded and published on the drain thread (never on the loop), which hands it to the
/// recording's own writer thread (encoding the 1 kHz stream, compressing, writing).
///
/// The feedback topic's vibrotactile channel is the high band of the contact force
/// (contact_rumble.h): an LR4 high-pass at `rumble_crossover_Hz` on the 1 kHz telemetry, its RMS
/// over each 60 Hz frame, scaled so that `rumble_full_scale_N` is 1.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "microcobot/live/camera_preview.h"
#include "microcobot/live/camera_snapshot.h"
#include "microcobot/live/console_pose_goal.h"
#include "microcobot/live/contact_rumble.h"
#include "microcobot/live/live_platform.h"
#include "microcobot/live/recording_files.h"
#include "microcobot/live/robot_frames.h"
#include "microcobot/live/session_recording.h"
#include "microcobot/runtime/timing_stats.h"
#include "microcobot/server/foxglove_server.h"

namespace mc::live {

struct ConsoleServerParams {
  server::ServerOptions server;   ///< listen address, port, token, limits
  std::filesystem::path out_dir;  ///< where recordings go (empty: recording disabled)
  /// Recordings recovered in out_dir at start (their stems): listed as recovered.
  std::vector<std::string> recovered;
  double telemetry_rate_Hz = 60.0;  ///< to clients (the recording keeps every sample)
  double status_rate_Hz = 5.0;
  double rumble_crossover_Hz = 100.0;  ///< the high band of the contact force
  double rumble_full_scale_N = 5e-6;   ///< high-band RMS that drives the rumble fully
  bool record_csv = false;             ///< recordings also write the telemetry as CSV (`serve --record-csv`)
  /// How recordings keep the camera unless their request says (`serve --record-video`).
  RecordedVideo record_video = RecordedVideo::kH264;
  H264Params h264;          ///< the recordings' H.264 encoder
  std::string version;      ///< the program's, into each recording's metadata
  std::string config_yaml;  ///< the platform configuration, into each recording
  void validate() const;
};

class ConsoleServer {
 public:
  /// `live` must outlive the server. Throws mc::Error (bad parameters).
  ConsoleServer(LivePlatform& live, ConsoleServerParams params);
  ~ConsoleServer();
  ConsoleServer(const ConsoleServer&) = delete;
  ConsoleServer& operator=(const ConsoleServer&) = delete;

  /// Binds (throws mc::InvalidInput when the address cannot be bound), starts the live platform
  /// and the status thread.
  /// Another consumer of the camera's frames (e.g. the DDS image topic, net/camera_image_publisher):
  /// `on_frame` runs on the camera thread after the console's channels; `wanted` (any thread)
  /// counts in the camera's demand. Before start().
  struct FrameConsumer {
    std::function<void(const devices::CameraFrame&, double t_s)> on_frame;
    std::function<bool()> wanted;
  };
  void add_frame_consumer(FrameConsumer consumer);
  /// Another consumer of the telemetry (e.g. the frames on DDS, net/tf_publisher): called on the
  /// drain thread with each sample sent to the clients (60 Hz), never on the loop. Before start().
  using SampleConsumer = std::function<void(const platform::TelemetrySample&)>;
  void add_sample_consumer(SampleConsumer consumer);
  /// The same with every sample (the loop's 1 kHz, e.g. the positioner's pose on DDS,
  /// net/positioner_pose_publisher): it must take little time, the drain waits for it.
  void add_every_sample_consumer(SampleConsumer consumer);
  void start();
  /// The console's URL, with the token when one is needed.
  std::string url() const;
  std::uint16_t port() const { return server_.port(); }
  /// Every device to its safe state, the recording closed (a valid MCAP file and its CSV),
  /// connections closed. Idempotent.
  void stop();

  /// Starts or stops a recording in out_dir: recording-YYYYmmdd-HHMMSS.mcap (the session:
  /// session_recording.h) and, with record_csv, the telemetry as recording-YYYYmmdd-HHMMSS.csv.
  /// `video`: how this recording keeps the camera (unset: record_video). Returns the MCAP file's
  /// name. Throws mc::InvalidInput when recording is disabled or a file cannot be created.
  std::string start_recording(std::optional<RecordedVideo> video = {});
  void stop_recording();
  /// What the last recording's H.264 encoder did (SessionRecording::video_stats; empty without
  /// --out).
  SessionRecording::VideoStats recording_video_stats() const;
  server::ServerCounters counters() const { return server_.counters(); }

 private:
  void on_sample(const platform::TelemetrySample& s, std::size_t count);
  /// A camera frame (camera thread): encoded, published and recorded.
  void on_frame(const devices::CameraFrame& f, double t_s);
  void on_message(const server::ClientMessage& m);
  void on_disconnect(server::ClientId client);
  void status_thread();
  /// The camera forms frames only while a client subscribes to them or a recording runs.
  void update_camera_demand();
  std::string status_json();
  std::string scene_json() const;
  /// The bodies of the 3-D view of the current scene, and their foxglove.SceneUpdate.
  RobotBodies robot_bodies() const;
  std::string robot_scene_json(double t_s) const;
  /// Publishes to the clients and records (loop time t_s).
  void publish(server::ChannelId ch, RecordedTopic topic, double t_s, const std::string& payload);
  /// A status to one client (0: every client), recorded as an event of `kind`.
  void tell(server::ClientId client, server::StatusLevel level, const std::string& message,
            std::string_view kind, std::string_view id = "");
  /// An event for the recording only.
  void note(EventLevel level, std::string_view kind, const std::string& message, server::ClientId client = 0);
  /// Events of what the status shows changing (demo, its phase, e-stop, errors); status thread.
  void note_changes(const LiveStatus& s);

  LivePlatform& live_;
  ConsoleServerParams params_;
  server::FoxgloveServer server_;
  /// The channels the server advertises (the camera's only with a camera).
  struct Channels {
    server::ChannelId telemetry = 0, status = 0, scene = 0, feedback = 0;
    server::ChannelId image = 0, info = 0, camera_state = 0, preview = 0;
    server::ChannelId tf = 0, robot_scene = 0;
  } ch_;
  RobotFrames frames_;                        // the 3-D view's frame tree, from the telemetry's channels
  std::optional<ConsolePoseGoal> pose_goal_;  // server thread: go-to pose (positioner: parallel)
  std::string image_cdr_, info_cdr_, preview_cdr_;      // camera thread only
  std::unique_ptr<CameraPreview> preview_;              // camera thread only
  std::unique_ptr<CameraSnapshot> snapshot_;            // null without a camera
  std::vector<FrameConsumer> frame_consumers_;          // set before start()
  std::vector<SampleConsumer> sample_consumers_;        // set before start()
  std::vector<SampleConsumer> every_sample_consumers_;  // set before start()

  std::atomic<server::ClientId> controller_{0};
  std::atomic<bool> quit_{false};
  std::thread status_;
  bool started_ = false;

  // Drain thread only.
  std::size_t decimation_ = 17, countdown_ = 0;
  ContactRumble rumble_;  // the feedback's vibrotactile channel
  std::string json_, tf_json_;
  runtime::TimingStats ticks_;      // the telemetry's tick_us, per second
  runtime::TimingStats ticks_cpu_;  // its tick_cpu_us, per second

  // The recording (fed by every thread, written by its own) and the recordings' folder.
  std::unique_ptr<SessionRecording> recording_;
  std::unique_ptr<RecordingFiles> files_;
  LiveStatus last_status_;  // status thread: what note_changes() compares with
  std::atomic<double> tick_p99_us_{0.0}, tick_cpu_p99_us_{0.0};
  runtime::TimingStats latency_{1e-5};    // status thread: command-to-target, 10 us bins
  runtime::TimingStats link_cost_{1e-8};  // status thread: the remote end's work per tick, 10 ns bins
};

}  // namespace mc::live

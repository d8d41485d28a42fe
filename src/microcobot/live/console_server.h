#pragma once
/// @file
/// The live platform served to its operators (issue #14, `microcobot serve`): the console page
/// over HTTP and the platform over the Foxglove WebSocket protocol (docs/console.md).
///
///   /platform/telemetry  60 Hz   the loop's telemetry (kTelemetryChannels), JSON
///   /platform/status      5 Hz   e-stop, control, watchdog, lifecycles, tick p99, recording
///   /platform/scene       1 Hz   geometry and limits the microscope view needs
///   /console/feedback    60 Hz   contact and grip forces, the vibrotactile channel
///   client /console/command      the controlling client's command (~30 Hz heartbeat)
///   client /console/action       estop, reset, take/release control, demo, restart, record
///
/// HTTP: `/` the console; `/recordings` the recordings in --out (JSON); `/recordings/<name>.mcap`
/// and `<name>.csv` downloads (not the one being written); `/recordings/<name>.html` its session report, made
/// on demand by a worker thread on the first request (the page reloads until it is ready) and
/// kept beside the recording.
///
/// One client controls at a time; the others observe until they take control. Any client may
/// press the e-stop. Every message is parsed, checked and clamped (console_command.h) before it
/// reaches the loop, through the live platform's single-producer ring (the server runs one I/O
/// thread: the one producer). Telemetry leaves the loop through the platform's ring and is
/// encoded, published and recorded on the drain thread, never on the loop.
///
/// The vibrotactile channel is the high band of the contact force, as the dual-stage
/// interface's crossover splits it (ch. 3): an LR4 high-pass at `rumble_crossover_Hz` on the
/// 1 kHz telemetry, its RMS over each 60 Hz frame, scaled so that `rumble_full_scale_N` is 1.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "microcobot/dsp/sos.h"
#include "microcobot/live/live_platform.h"
#include "microcobot/platform/timing_stats.h"
#include "microcobot/server/foxglove_server.h"

namespace mc {
class CsvStreamWriter;
class McapWriter;
}  // namespace mc

namespace mc::live {

struct ConsoleServerParams {
  server::ServerOptions server;     ///< listen address, port, token, limits
  std::filesystem::path out_dir;    ///< where recordings go (empty: recording disabled)
  double telemetry_rate_Hz = 60.0;  ///< to clients (the recording keeps every sample)
  double status_rate_Hz = 5.0;
  double rumble_crossover_Hz = 100.0;  ///< the high band of the contact force
  double rumble_full_scale_N = 5e-6;   ///< high-band RMS that drives the rumble fully
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
  void start();
  /// The console's URL, with the token when one is needed.
  std::string url() const;
  std::uint16_t port() const { return server_.port(); }
  /// Every device to its safe state, the recording closed (a valid MCAP file and its CSV),
  /// connections closed. Idempotent.
  void stop();

  /// Starts or stops a recording in out_dir: recording-YYYYmmdd-HHMMSS.mcap (JSON messages on
  /// /platform/telemetry) and the same samples as recording-YYYYmmdd-HHMMSS.csv (a column per
  /// channel). Throws mc::InvalidInput when recording is disabled or a file cannot be created.
  void start_recording();
  void stop_recording();
  server::ServerCounters counters() const { return server_.counters(); }

  /// Recordings longer than this are refused a report (the reader holds the file in memory).
  static constexpr std::uintmax_t kMaxReportRecordingBytes = 512ull << 20;
  /// Samples a report plots at most (evenly decimated).
  static constexpr std::size_t kReportSamples = 20000;

 private:
  void on_sample(const platform::TelemetrySample& s, std::size_t count);
  void on_message(const server::ClientMessage& m);
  void on_disconnect(server::ClientId client);
  void status_thread();
  std::string status_json();
  std::string scene_json() const;
  std::optional<server::HttpReply> on_http(std::string_view path);
  std::string recordings_json() const;
  server::HttpReply report_reply(const std::string& stem);
  void make_report(const std::string& stem);

  LivePlatform& live_;
  ConsoleServerParams params_;
  server::FoxgloveServer server_;
  server::ChannelId telemetry_ch_ = 0, status_ch_ = 0, scene_ch_ = 0, feedback_ch_ = 0;

  std::atomic<server::ClientId> controller_{0};
  std::atomic<bool> quit_{false};
  std::thread status_;
  bool started_ = false;

  // Drain thread only.
  std::size_t decimation_ = 17, countdown_ = 0;
  dsp::SosFilter rumble_x_, rumble_y_, rumble_z_;
  double rumble_sum_ = 0.0;
  std::size_t rumble_n_ = 0;
  std::string json_;
  platform::TimingStats ticks_;      // the telemetry's tick_us, per second
  platform::TimingStats ticks_cpu_;  // its tick_cpu_us, per second

  // Recording: written on the drain thread, opened and closed by the server thread.
  mutable std::mutex recording_mutex_;
  std::unique_ptr<McapWriter> recording_;
  std::unique_ptr<CsvStreamWriter> recording_csv_;  ///< the same samples beside it
  std::uint16_t recording_channel_ = 0;
  std::string recording_name_;
  std::atomic<double> tick_p99_us_{0.0}, tick_cpu_p99_us_{0.0};
  platform::TimingStats latency_{1e-5};    // status thread: command-to-target, 10 us bins
  platform::TimingStats link_cost_{1e-8};  // status thread: the remote end's work per tick, 10 ns bins

  // Reports made on demand, one at a time, off the server's I/O thread.
  std::mutex report_mutex_;
  std::thread report_thread_;
  std::string reporting_;                             // the stem being made, empty when idle
  std::map<std::string, std::string> report_errors_;  // stem -> why its report failed
};

}  // namespace mc::live

#include "microcobot/deployment/deployment.h"

#include <fstream>
#include <system_error>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/core/params.h"
#include "microcobot/deployment/live_setup.h"
#include "microcobot/deployment/remote_role.h"
#include "microcobot/live/recording_recovery.h"
#include "microcobot/net/camera_image_publisher.h"
#include "microcobot/net/cyclone_config.h"
#include "microcobot/net/microscope_link.h"
#include "microcobot/net/positioner_pose_publisher.h"
#include "microcobot/net/tf_publisher.h"
#include "microcobot/twins/live_stage.h"
#include "microcobot/twins/twin_server.h"

#ifndef MC_VERSION
#error "MC_VERSION: the library's version, defined by the build (src/microcobot/CMakeLists.txt)"
#endif

namespace mc::deployment {
namespace {

bool is_loopback(const std::string& host) {
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

// A token for a server reachable from the network: 128 bits from the kernel's generator.
std::string random_token() {
  std::ifstream in("/dev/urandom", std::ios::binary);
  unsigned char bytes[16];
  if (!in.read(reinterpret_cast<char*>(bytes), sizeof bytes))
    throw InvalidInput("/dev/urandom: cannot read a token; give one with --token");
  std::string t;
  for (unsigned char b : bytes) t += fmt::format("{:02x}", b);
  return t;
}

}  // namespace

std::string_view role_name(Role role) {
  switch (role) {
    case Role::kMaster:
      return "master";
    case Role::kSlave:
      return "slave";
    case Role::kSingle:
      break;
  }
  return "single";
}

live::RecordedVideo parse_record_video(std::string_view text) {
  if (const auto v = live::parse_recorded_video(text)) return *v;
  throw UsageError("--record-video: '" + excerpt(text) + "' must be h264, jpeg or off");
}

Deployment::Deployment(ServeConfig config, Log log) : config_(std::move(config)), log_(std::move(log)) {
  if (!log_) log_ = [](const std::string&) {};
  const ServeConfig& o = config_;
  live::LiveParams lp = live_params(o, log_);

  live::ConsoleServerParams sp;
  sp.server.address = o.listen_address;
  sp.server.port = o.listen_port;
  sp.server.token = o.token;
  if (sp.server.token.empty() && !is_loopback(o.listen_address)) sp.server.token = random_token();
  if (!sp.server.token.empty() && (sp.server.token.size() < 8 || sp.server.token.size() > 256 ||
                                   sp.server.token.find_first_of(" &#?%/\"'<>") != std::string::npos))
    throw UsageError("--token: must be 8 to 256 characters without spaces or any of &#?%/\"'<>");
  sp.out_dir = o.out;
  sp.record_csv = o.record_csv;
  sp.record_video = o.record_video;
  // Each recording holds the program's version and the configuration it ran (as --print-config
  // prints it: the keys --config takes), so a recording alone says what was run.
  sp.version = std::string("microcobot ") + MC_VERSION;
  sp.config_yaml = params_to_yaml(lp.platform);
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  if (ec) throw InvalidInput("cannot create --out " + excerpt(o.out.string()) + ": " + ec.message());
  if (!std::filesystem::is_directory(o.out, ec))
    throw InvalidInput("--out " + excerpt(o.out.string()) + ": exists and is not a directory");
  for (const live::RecoveredRecording& r : live::recover_unfinished_recordings(o.out)) {
    if (!r.error.empty()) {
      log_("could not recover " + r.from.string() + ", left by an earlier run: " + r.error);
      continue;
    }
    log_(fmt::format("recovered {} from {}, left unfinished by an earlier run: {} messages over {:.1f} s{}",
                     r.to.string(), r.from.filename().string(), r.messages, r.duration_s,
                     r.lost_bytes == 0
                         ? std::string()
                         : fmt::format(" (its last {} bytes, a cut record, dropped)", r.lost_bytes)));
    sp.recovered.push_back(r.to.stem().string());
  }

  twin_token_ = sp.server.token;
  for (const auto& t : o.twins)
    if (twin_token_.empty() && !is_loopback(t.address)) twin_token_ = random_token();
  RemoteEnds ends = attach_role(o, lp);
  remote_slave_ = std::move(ends.slave);
  remote_master_ = std::move(ends.master);
  // What is simulated and what a driver runs: the stage's devices, and the parallel positioner.
  std::string on = lp.platform.devices.simulated() ? std::string("the simulated devices")
                                                   : "the drivers '" + lp.platform.devices.driver + "' (" +
                                                         lp.platform.devices.connection + ")";
  if (lp.platform.parallel_positioner_enabled()) {
    const platform::ParallelPositionerSelection& pp = lp.platform.parallel_positioner;
    on += pp.simulated()
              ? std::string(", the parallel positioner simulated") +
                    (pp.controller_on_thread() ? " (its legs on their controller's thread)"
                                               : " (its legs on the loop)")
              : ", the parallel positioner on the driver '" + pp.driver + "' (" + pp.connection + ")";
  }
  log_("building the platform (the stick-slip step map takes about a second) on " + on);
  const net::NetworkConfig network = o.network.value_or(net::NetworkConfig{});
  if (o.role != Role::kSingle)
    log_(fmt::format(
        "{} of a distributed platform on DDS domain {} ({}; the peer: serve --role {} --domain {})",
        role_name(o.role), o.domain, net::describe(network), o.role == Role::kMaster ? "slave" : "master",
        o.domain));
  live_ = std::make_unique<live::LivePlatform>(lp);
  live::LivePlatform& live = *live_;
  // The slave's camera on DDS as a ROS 2 image topic (built before the server that calls it).
  if (o.role == Role::kSlave && live.has_camera())
    images_ = std::make_unique<net::CameraImagePublisher>(o.domain, network);
  // The slave's frames on DDS as ROS 2's /tf.
  if (o.role == Role::kSlave)
    frames_ = std::make_unique<net::TfPublisher>(o.domain, network, live.telemetry_schema(),
                                                 live.params().platform.parallel_positioner_enabled()
                                                     ? &live.params().platform.parallel_positioner.geometry
                                                     : nullptr);
  // With a parallel positioner, its pose as a state topic of its own.
  if (o.role == Role::kSlave && net::PositionerPosePublisher::fits(live.telemetry_schema()))
    positioner_pose_ =
        std::make_unique<net::PositionerPosePublisher>(o.domain, network, live.telemetry_schema());
  // The microscope's focus and turret on DDS: the slave takes them from any peer, the master
  // sends its operator's (net/microscope_link.h).
  if (o.role == Role::kSlave && live.has_camera()) {
    microscope_server_ = std::make_unique<net::MicroscopeServer>(
        o.domain, network,
        [&live](const net::MicroscopeJoints& j) {
          live::ConsoleCommand c;
          c.has_focus = j.has_focus;
          c.focus_z_m = j.focus_z_m;
          c.objective = j.objective;
          live.push_microscope_command(c);  // a full ring (16 waiting) drops it: the next one counts
        },
        [&live] { return microscope_joints(live, false); });
    log_(
        fmt::format("the microscope's focus and objective on DDS, ROS 2 topics {} and {} "
                    "(sensor_msgs/msg/JointState)",
                    net::kMicroscopeCommandRosName, net::kMicroscopeStateRosName));
  }
  if (o.role == Role::kMaster && live.has_camera())
    microscope_client_ = std::make_unique<net::MicroscopeClient>(
        o.domain, network, [&live] { return microscope_joints(live, true); });
  server_ = std::make_unique<live::ConsoleServer>(live, sp);
  if (images_) {
    server_->add_frame_consumer(
        {[p = images_.get()](const devices::CameraFrame& f, double t_s) { p->publish(f, t_s); },
         [p = images_.get()] { return p->wanted(); }});
    log_(fmt::format("camera images on DDS, ROS 2 topic {} ({})", net::kCameraImageRosName,
                     net::kCameraImageTypeName));
  }
  if (frames_) {
    server_->add_sample_consumer([p = frames_.get()](const platform::TelemetrySample& s) { p->publish(s); });
    log_(fmt::format("the tool, gripper, fingers and part on DDS, ROS 2 topic {} ({})", net::kTfRosName,
                     net::kTfTypeName));
  }
  if (positioner_pose_) {
    server_->add_every_sample_consumer(
        [p = positioner_pose_.get()](const platform::TelemetrySample& s) { p->publish(s); });
    log_(fmt::format("the parallel positioner's pose on DDS, ROS 2 topic {} ({})",
                     net::kPositionerPoseTopic.ros_name, net::kPositionerPoseTopic.type_name));
  }
  // The vendor-protocol twins: their own thread, the live platform reached through its ring.
  if (!o.twins.empty()) {
    twins::TwinServerParams tp;
    tp.endpoints = o.twins;
    for (const auto& t : o.twins)
      if (t.protocol == twins::Protocol::kMcs2) tp.mcs2.no_sensor_channels |= t.no_sensor_channels;
    tp.token = twin_token_;
    tp.gcs2.idn = std::string("microcobot, E-873 digital twin, 0, ") + MC_VERSION;
    tp.gcs2_hexapod.idn = std::string("microcobot, C-887 digital twin, 0, ") + MC_VERSION;
    twin_stage_ = std::make_unique<twins::LiveStage>(live);
    twin_server_ = std::make_unique<twins::TwinServer>(*twin_stage_, tp);
  }
  config_.platform = lp.platform;
  config_.token = sp.server.token;
}

Deployment::~Deployment() { stop(); }

void Deployment::start() {
  if (started_) throw InvalidInput("deployment: already started");
  started_ = true;
  server_->start();
  if (twin_server_) twin_server_->start();
  if (config_.record) server_->start_recording();
}

void Deployment::stop() {
  if (twin_server_) twin_server_->stop();  // its clients gone: the stage holds
  if (server_) server_->stop();            // every device in its safe state, the recording closed
}

std::string Deployment::url() const { return server_->url(); }

std::uint16_t Deployment::port() const { return server_->port(); }

std::vector<ServedTwin> Deployment::twins() const {
  std::vector<ServedTwin> served;
  if (!twin_server_) return served;
  const std::vector<std::uint16_t> ports = twin_server_->ports();
  for (std::size_t k = 0; k < config_.twins.size() && k < ports.size(); ++k)
    served.push_back({config_.twins[k].protocol, twins::protocol_name(config_.twins[k].protocol),
                      config_.twins[k].address, ports[k], !is_loopback(config_.twins[k].address)});
  return served;
}

std::optional<PortEnergy> Deployment::port_energy() const {
  if (remote_slave_)
    return PortEnergy{remote_slave_->min_observed_energy_J(), remote_slave_->dissipated_energy_J()};
  if (remote_master_)
    return PortEnergy{remote_master_->min_observed_energy_J(), remote_master_->dissipated_energy_J()};
  return std::nullopt;
}

}  // namespace mc::deployment

#pragma once
/// @file
/// The live system as one object: what `microcobot serve` runs, assembled from a ServeConfig.
///
///   ServeConfig --> live::LiveParams (scene, cell part, remote devices or command source)
///               --> live::LivePlatform (the loop, its threads)
///               --> DDS ends of the role (net::RemoteSlave or net::RemoteMaster), the
///                   microscope link, the camera's ROS 2 image topic (slave)
///               --> live::ConsoleServer (HTTP + Foxglove WebSocket, recordings)
///               --> twins::TwinServer on a twins::LiveStage (the vendor protocols)
///
/// Construction checks the configuration and builds everything (about a second: the stick-slip
/// step map); nothing listens until start(). stop() (or the destructor) closes the twins first
/// (their clients gone, the stage holds), then the console server, which stops the live platform:
/// every device in its safe state, the recording closed.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "microcobot/deployment/serve_config.h"
#include "microcobot/live/console_server.h"
#include "microcobot/live/live_platform.h"

namespace mc::net {
class CameraImagePublisher;
class PositionerPosePublisher;
class TfPublisher;
class MicroscopeClient;
class MicroscopeServer;
class RemoteMaster;
class RemoteSlave;
}  // namespace mc::net

namespace mc::twins {
class LiveStage;
class TwinServer;
}  // namespace mc::twins

namespace mc::deployment {

/// A vendor twin as served: its protocol's name (twins::protocol_name), address and bound port.
struct ServedTwin {
  twins::Protocol protocol = twins::Protocol::kGcs2;
  std::string name;
  std::string address;
  std::uint16_t port = 0;
  bool token_required = false;  ///< off loopback: clients must give Deployment::twin_token()
};

/// The energy balance of this end's ports of the master-slave channel (master or slave role).
struct PortEnergy {
  double lowest_observed_J = 0.0;  ///< the lowest energy the passivity observer saw
  double refused_J = 0.0;          ///< what the passivity controller dissipated
};

class Deployment {
 public:
  /// Checks `config` and builds the deployment; nothing is served yet. `log` receives a line per
  /// part assembled (may be empty). Throws mc::UsageError when fields contradict each other (named
  /// by their `serve` flag, exit 2), mc::InvalidInput (a scene, task or configuration file, the
  /// out directory, exit 3), mc::InvalidParams, or mc::Error from DDS.
  explicit Deployment(ServeConfig config, Log log = {});
  /// stop().
  ~Deployment();
  Deployment(const Deployment&) = delete;
  Deployment& operator=(const Deployment&) = delete;

  /// Binds the console server and starts the live platform, then the twins, then a recording
  /// (`record`). Throws mc::InvalidInput naming an address that cannot be bound.
  void start();
  /// The twins closed (the stage holds), then the console server and the live platform: every
  /// device in its safe state, the recording closed. Idempotent.
  void stop();

  /// The console's URL (with the token when one is needed); after start().
  std::string url() const;
  /// The console's bound port; after start().
  std::uint16_t port() const;
  /// The twins in the order of `config().twins`, with their bound ports; after start().
  std::vector<ServedTwin> twins() const;
  /// The token the twins ask of clients off loopback (empty when all are on loopback).
  const std::string& twin_token() const { return twin_token_; }
  /// This end's ports of the master-slave channel; none in the single role.
  std::optional<PortEnergy> port_energy() const;

  /// The configuration as resolved (the configuration file loaded, the scene applied, a token
  /// drawn when one is needed).
  const ServeConfig& config() const { return config_; }
  live::LivePlatform& live() { return *live_; }
  live::ConsoleServer& console() { return *server_; }

 private:
  ServeConfig config_;
  Log log_;
  std::string twin_token_;
  // Declared in the order of construction: the members below use those above, and are destroyed
  // before them.
  std::unique_ptr<net::RemoteSlave> remote_slave_;
  std::unique_ptr<net::RemoteMaster> remote_master_;
  std::unique_ptr<live::LivePlatform> live_;
  std::unique_ptr<net::CameraImagePublisher> images_;
  std::unique_ptr<net::TfPublisher> frames_;
  std::unique_ptr<net::PositionerPosePublisher> positioner_pose_;  // with a parallel positioner
  std::unique_ptr<net::MicroscopeServer> microscope_server_;
  std::unique_ptr<net::MicroscopeClient> microscope_client_;
  std::unique_ptr<live::ConsoleServer> server_;
  std::unique_ptr<twins::LiveStage> twin_stage_;
  std::unique_ptr<twins::TwinServer> twin_server_;
  bool started_ = false;
};

}  // namespace mc::deployment

#pragma once
/// @file
/// What a live deployment is made of (`microcobot serve`): the platform's configuration and
/// scene, where the console listens and records, this process's role in a distributed platform,
/// and the vendor-protocol twins. A `Deployment` (deployment.h) assembles and runs it; the CLI
/// only parses its flags into one.
///
/// Each field is one `serve` flag (named beside it); the Deployment's errors name the flag, so
/// that a message reads the same from the command line and from a program.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "microcobot/live/recorded_video.h"
#include "microcobot/net/cyclone_config.h"
#include "microcobot/platform/platform_config.h"
#include "microcobot/teleop/link_emulator.h"
#include "microcobot/twins/twin_server.h"

namespace mc::deployment {

/// Which part of the platform this process runs (`--role`).
enum class Role {
  kSingle,  ///< the whole platform here
  kMaster,  ///< the operator's side (console, masters, coupling); the stage is the slave process's
  kSlave,   ///< stage, gripper, microworld, stage controller; commands from the master process
};

/// "single", "master" or "slave".
std::string_view role_name(Role role);

/// `--record-video`'s value: "h264", "jpeg" or "off". Throws mc::UsageError naming the flag and
/// what was given.
live::RecordedVideo parse_record_video(std::string_view text);

/// One line of what a deployment assembles (no newline); `serve` prints it on stderr.
using Log = std::function<void(const std::string& line)>;

struct ServeConfig {
  /// The platform's configuration (the keys `run --print-config` prints).
  platform::PlatformConfig platform;
  /// `--config`: a YAML file loaded in place of `platform`.
  std::optional<std::filesystem::path> config_file;
  /// `--scene`: pick-place (unset), pin-in-hole, optical-trap or a YAML file of the microworld's
  /// keys; with `cell`, the batch's YAML file (cell::AssemblyBatchParams).
  std::optional<std::string> scene;
  /// `--cell`: one part of a batch inserted by the automatic task the console supervises.
  bool cell = false;
  std::optional<int> seed;                    ///< `--seed`: the batch's (cell only)
  std::optional<int> part;                    ///< `--part`: which part of the batch (cell only; default 0)
  std::optional<std::filesystem::path> task;  ///< `--task`: a task file (cell only; cell/task_file.h)
  bool cell_camera = false;                   ///< `--cell-camera`: the cell camera's looks (cell only)

  /// `--listen`: the console's address and port (0: a free one). Off loopback a token is needed:
  /// one is drawn when `token` is empty.
  std::string listen_address = "127.0.0.1";
  std::uint16_t listen_port = 8080;
  std::string token;  ///< `--token`: 8 to 256 characters without spaces or any of &#?%/"'<>

  std::filesystem::path out = "out/live";  ///< `--out`: the recordings' directory (created)
  bool record = false;                     ///< `--record`: start recording at once
  bool record_csv = false;                 ///< `--record-csv`: each recording's telemetry also as CSV
  /// `--record-video`: how recordings keep the camera, unless the console's request says
  /// (live/recorded_video.h).
  live::RecordedVideo record_video = live::RecordedVideo::kH264;

  /// `--role`; `domain`, `network`, `link` and `passivity` are the DDS link's (master or slave).
  Role role = Role::kSingle;
  int domain = 0;  ///< `--domain`: the DDS domain id, [0, net::kMaxDomainId]
  /// `--interface`, `--peer`: where the link's traffic goes (unset: loopback).
  std::optional<net::NetworkConfig> network;
  teleop::LinkParams link;  ///< `--link-delay`, `--link-jitter`, `--link-loss`: what this end receives
  bool passivity = true;    ///< `--passivity`: time-domain passivity control at this end's ports

  /// `--emulate`: the vendor-protocol twins served on the live stage (twins::parse_emulate).
  std::vector<twins::TwinEndpoint> twins;
};

}  // namespace mc::deployment

// `microcobot serve`: the platform live. Builds the platform (simulated devices),
// runs its loop paced to the wall clock and serves the operator's console over HTTP and the
// Foxglove WebSocket protocol (docs/console.md). The first line on stdout is the console's URL.
// Runs until SIGINT/SIGTERM, then puts every device in its safe state, closes the recording
// and exits 0. The flags fill a deployment::ServeConfig; deployment::Deployment assembles and
// runs what it describes.

#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>
#include <tuple>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/deployment/deployment.h"
#include "microcobot/net/cyclone_config.h"
#include "microcobot/runtime/allocator.h"
#include "network_options.h"
#include "signals.h"

namespace serve_commands {
namespace {

namespace dp = mc::deployment;

// The flags: those of the deployment's own type straight into its ServeConfig, the others as
// typed and converted by serve_config().
struct ServeOptions {
  dp::ServeConfig config;
  std::string listen = "127.0.0.1:8080";
  double duration_s = 0.0;
  std::string role = "single";        // single | master | slave
  mc::cli::NetworkOptions network;    // where the DDS link goes (master and slave roles)
  std::string passivity = "on";       // time-domain passivity control at this end's ports
  std::string record_video = "h264";  // h264 | jpeg | off
  std::vector<std::string> emulate;   // vendor-protocol twins: gcs2[=ADDR:PORT], ..., gcs2-hexapod[=...]
};

// "HOST:PORT" or "[V6]:PORT".
std::pair<std::string, std::uint16_t> parse_listen(const std::string& text) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == text.size())
    throw mc::UsageError("--listen: '" + mc::excerpt(text) + "' must be ADDRESS:PORT (e.g. 127.0.0.1:8080)");
  std::string host = text.substr(0, colon);
  if (host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  const std::string port = text.substr(colon + 1);
  if (port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos ||
      std::stoul(port) > 65535)
    throw mc::UsageError("--listen: port '" + mc::excerpt(port) + "' must be a number within [0, 65535]");
  return {host, static_cast<std::uint16_t>(std::stoul(port))};
}

dp::ServeConfig serve_config(const ServeOptions& o) {
  dp::ServeConfig c = o.config;
  std::tie(c.listen_address, c.listen_port) = parse_listen(o.listen);
  c.role = o.role == "master" ? dp::Role::kMaster : o.role == "slave" ? dp::Role::kSlave : dp::Role::kSingle;
  c.passivity = o.passivity == "on";
  c.record_video = dp::parse_record_video(o.record_video);
  if (o.network.given()) c.network = mc::cli::network_config(o.network);
  for (const auto& e : o.emulate) c.twins.push_back(mc::twins::parse_emulate(e));
  return c;
}

void serve(const ServeOptions& o) {
  const dp::ServeConfig config = serve_config(o);
  // A session of hours: frames, encoded images and recording chunks mapped and unmapped whole,
  // not left to fragment the threads' arenas (runtime/allocator.h). Where the C library
  // is not glibc its own policy stays.
  mc::runtime::keep_large_blocks_mapped();
  mc::cli::set_cooperative_interrupts(true);
  dp::Deployment deployment(config, [](const std::string& line) { std::cerr << "serve: " << line << "\n"; });
  deployment.start();
  // The first line on stdout: what the operator opens; then one line per twin.
  std::cout << deployment.url() << std::endl;
  for (const dp::ServedTwin& t : deployment.twins()) {
    std::cout << "emulate " << t.name << " " << t.address << ":" << t.port << std::endl;
    std::cerr << "serve: " << t.name << " twin on " << t.address << ":" << t.port
              << (t.token_required ? " (token " + deployment.twin_token() + ")" : "") << "\n";
  }
  std::cerr << "serve: console at " << deployment.url() << " (Ctrl-C stops: devices to their safe state)\n";
  const std::string& host = config.listen_address;
  if (host == "0.0.0.0" || host == "::")
    std::cerr
        << "serve: listening on every interface: from another machine, open this machine's address on port "
        << deployment.port() << " with the same token\n";
  const auto start = std::chrono::steady_clock::now();
  while (mc::cli::interrupt_signal() == 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (o.duration_s > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= o.duration_s)
      break;
  }
  deployment.stop();
  mc::cli::set_cooperative_interrupts(false);
  if (const std::optional<dp::PortEnergy> e = deployment.port_energy())
    std::cerr << fmt::format(
        "serve: this end's ports (passivity control {}): lowest observed energy {:.3g} J, {:.3g} J refused\n",
        o.passivity, e->lowest_observed_J, e->refused_J);
  const int sig = mc::cli::interrupt_signal();
  std::cerr << "serve: stopped" << (sig ? " on " + mc::cli::signal_name(sig) : std::string())
            << ": every device in its safe state, recordings closed in " << config.out.string() << "\n";
}

void add_serve(CLI::App& cmd) {
  auto o = std::make_shared<ServeOptions>();
  cmd.add_option("--config", o->config.config_file,
                 "Platform configuration (YAML; keys as `run --print-config` shows)");
  cmd.add_option(
      "--scene", o->config.scene,
      "Scene: pick-place (default: the 300 um part), pin-in-hole (a 200 um pin into a hole with "
      "20 um of clearance), optical-trap (a 3 um bead in optical tweezers, touching a stuck "
      "bead) or a YAML file of the microworld's keys (scenes/*.yaml); with --cell, the batch (YAML; "
      "`cell params` shows its keys under scene)");
  cmd.add_flag("--cell", o->config.cell,
               "The assembly cell: one part of a batch (--scene, --seed, --part) inserted by the automatic "
               "task, which the console starts, pauses, takes over and hands back (docs/cell.md)");
  cmd.add_option("--seed", o->config.seed, "With --cell: the batch's seed (default 1)")
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--part", o->config.part, "With --cell: which part of the batch (default 0)")
      ->check(CLI::Range(0, 9999));
  cmd.add_option(
      "--task", o->config.task,
      "With --cell: a task file (YAML: `steps` autonomy auto|confirm|manual, `params` of the task; "
      "docs/cell.md)");
  cmd.add_flag("--cell-camera", o->config.cell_camera,
               "With --cell: the cell's camera looks at the pin in its slot, in the fingers and placed "
               "(rendered frames; the task holds while it looks; docs/cell.md)");
  cmd.add_option("--listen", o->listen,
                 "Address and port (default 127.0.0.1:8080; port 0 picks a free one; any non-loopback "
                 "address requires a token)");
  cmd.add_option("--token", o->config.token,
                 "Token the WebSocket clients must give (generated off loopback)");
  cmd.add_option(
      "--emulate", o->emulate,
      "Serve a vendor protocol on the live stage (repeatable): gcs2[=ADDR:PORT] (PI GCS 2.0, default "
      "127.0.0.1:50000), anc300[=ADDR:PORT] (Attocube ANC300 console, default 127.0.0.1:7230), "
      "mcs2[=ADDR:PORT][,no_sensor=N[+M]] (SmarAct MCS2 ASCII, default 127.0.0.1:55551; no_sensor: channels "
      "without a sensor, stepped open loop only) or gcs2-hexapod[=ADDR:PORT] (PI C-887 hexapod dialect over "
      "the platform's 6-DOF parallel positioner, which it then carries (positioner: parallel), default "
      "127.0.0.1:50000); docs/hardware.md");
  cmd.add_option("--out", o->config.out, "Directory of the MCAP recordings (default out/live)");
  cmd.add_flag("--record", o->config.record, "Start recording at once (else from the console)");
  cmd.add_flag("--record-csv", o->config.record_csv,
               "Also write each recording's telemetry as CSV beside its MCAP file (off: the MCAP file "
               "holds every sample; the console offers the CSV when it exists)");
  cmd.add_option(
      "--record-video", o->record_video,
      "How recordings keep the camera: h264 (default: H.264 as foxglove.CompressedVideo on "
      "/camera/video, keyframes every 2 s at most), jpeg (each frame's JPEG on "
      "/camera/image/compressed, as the console's channel) or off (no camera channel); the console's "
      "record request may choose otherwise");
  cmd.add_option("--duration", o->duration_s,
                 "Stop after this many seconds of wall-clock time (default: never)")
      ->check(mc::cli::Range(0.0, 1e7));
  cmd.add_option("--role", o->role,
                 "single (default: the whole platform here), master (the operator's side: console, masters, "
                 "coupling; the stage is the slave process's) or slave (stage, gripper, microworld, stage "
                 "controller; commands from the master process), joined over DDS (docs/distributed.md)")
      ->check(CLI::IsMember({"single", "master", "slave"}));
  cmd.add_option(
         "--domain", o->config.domain,
         fmt::format("DDS domain id of the master-slave link, 0 to {} (default 0; both ends the same)",
                     mc::net::kMaxDomainId))
      ->check(CLI::Range(0, mc::net::kMaxDomainId));
  mc::cli::add_network_options(cmd, o->network);
  cmd.add_option("--link-delay", o->config.link.delay_s,
                 "Emulated one-way delay of what this end receives, s (default 0; both ends: a round trip "
                 "of twice it)")
      ->check(mc::cli::Range(0.0, 10.0));
  cmd.add_option("--link-jitter", o->config.link.jitter_s,
                 "Emulated jitter, s: each delay uniform in delay +- jitter (default 0; at most the delay)")
      ->check(mc::cli::Range(0.0, 10.0));
  cmd.add_option(
         "--link-loss", o->config.link.loss,
         "Emulated probability of losing a best-effort sample, [0, 1) (default 0; the reliable e-stop "
         "and engaged topics are only delayed)")
      ->check(mc::cli::Range(0.0, 0.999));
  cmd.add_option("--passivity", o->passivity,
                 "Time-domain passivity control at this end's ports of the master-slave channel: on "
                 "(default; keeps the coupling passive under delay and loss, docs/concepts/teleoperation.md) "
                 "or off (observed only). Needs --role")
      ->check(CLI::IsMember({"on", "off"}));
  cmd.callback([o] { serve(*o); });
}

const bool kRegistered = mc::cli::register_group(
    {"serve", "Run the platform live: the operator's console in a browser, Foxglove WebSocket, MCAP", 6,
     &add_serve});

}  // namespace
}  // namespace serve_commands

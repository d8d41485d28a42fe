// `microcobot serve`: the platform live. Builds the platform (simulated devices),
// runs its loop paced to the wall clock and serves the operator's console over HTTP and the
// Foxglove WebSocket protocol (docs/console.md). The first line on stdout is the console's URL.
// Runs until SIGINT/SIGTERM, then puts every device in its safe state, closes the recording
// and exits 0.

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <thread>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/cell/assembly_batch.h"
#include "microcobot/cell/task_file.h"
#include "microcobot/cell/task_io.h"
#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/core/params.h"
#include "microcobot/live/console_server.h"
#include "microcobot/live/live_platform.h"
#include "microcobot/net/camera_image_publisher.h"
#include "microcobot/net/cyclone_config.h"
#include "microcobot/net/microscope_link.h"
#include "microcobot/net/remote_camera.h"
#include "microcobot/net/remote_master.h"
#include "microcobot/net/remote_slave.h"
#include "microcobot/platform/driver_registry.h"
#include "microcobot/platform/platform_config.h"
#include "microcobot/twins/live_stage.h"
#include "microcobot/twins/twin_server.h"
#include "network_options.h"
#include "signals.h"

namespace serve_commands {
namespace {

namespace pf = mc::platform;

struct ServeOptions {
  std::optional<std::filesystem::path> config;
  std::optional<std::string> scene;  // default pick-place; with --cell, the batch (AssemblyBatchParams)
  bool cell = false;                 // the automatic insertion supervised from the console
  std::optional<int> seed, part;     // --cell: the batch's seed, the part of it
  std::optional<std::filesystem::path> task;  // --cell: a task file (cell/task_file.h)
  bool cell_camera = false;                   // --cell: the cell camera's looks (cell/cell_camera.h)
  std::string listen = "127.0.0.1:8080";
  std::string token;
  std::filesystem::path out = "out/live";
  bool record = false;
  bool record_csv = false;
  double duration_s = 0.0;
  std::string role = "single";  // single | master | slave
  int domain = 0;
  mc::cli::NetworkOptions network;   // where the DDS link goes (master and slave roles)
  mc::teleop::LinkParams link;       // the emulated impairment of what this end receives
  std::string passivity = "on";      // time-domain passivity control at this end's ports
  std::vector<std::string> emulate;  // vendor-protocol twins: gcs2[=ADDR:PORT], anc300[=...]
};

// The distributed platform's far end: the master process sees the slave stage as
// remote devices, the slave process takes its commands from the remote master.
struct RemoteEnds {
  std::unique_ptr<mc::net::RemoteSlave> slave;
  std::unique_ptr<mc::net::RemoteMaster> master;
};

RemoteEnds attach_role(const ServeOptions& o, mc::live::LiveParams& lp) {
  RemoteEnds ends;
  if (o.role == "single") {
    if (mc::net::impairs(o.link))
      throw mc::UsageError("--link-delay, --link-jitter, --link-loss: need --role master or slave");
    if (o.network.given()) throw mc::UsageError("--interface, --peer: need --role master or slave");
    if (o.passivity != "on") throw mc::UsageError("--passivity: needs --role master or slave");
    return ends;
  }
  if (o.link.jitter_s > o.link.delay_s)
    throw mc::UsageError(
        "--link-jitter: must not exceed --link-delay (delays are delay +- jitter, never negative)");
  const mc::stickslip::StickSlipParams axis = pf::axis_params(lp.platform);
  if (o.role == "master") {
    mc::net::RemoteSlaveParams rp;
    rp.link.domain_id = o.domain;
    rp.link.network = mc::cli::network_config(o.network);
    rp.emulate = o.link;
    rp.passivity = o.passivity == "on";
    rp.sample_period_s = axis.integrator.dt_s;
    rp.max_voltage_V = axis.drive.max_V;
    rp.rotary = lp.platform.stage.rotary;  // the slave's rotary axis (the same configuration)
    rp.rotary.enabled = rp.rotary.enabled && !lp.platform.optical_trap_scene();
    ends.slave = std::make_unique<mc::net::RemoteSlave>(rp);
    // The masters are this machine's (simulated, the operator then uses the console, or the
    // drivers' masters: their stage and gripper, built but never configured, are not opened);
    // the stage is the slave process's.
    lp.make_devices = [remote = ends.slave.get(), cfg = lp.platform, domain = o.domain,
                       network = mc::cli::network_config(o.network)] {
      mc::devices::DeviceSet d;
      if (cfg.devices.simulated()) {
        d.haptic = std::make_unique<mc::devices::SimulatedHapticMaster>(
            "dual_stage", cfg.haptic.plant, cfg.haptic.render, cfg.haptic.pantograph, cfg.loop.period_s());
        d.tweezers = std::make_unique<mc::devices::SimulatedTweezersMaster>("teletweez", cfg.tweezers,
                                                                            cfg.loop.period_s());
      } else {
        d = pf::make_driver_devices(cfg);
      }
      mc::devices::DeviceSet stage = remote->make_devices();
      d.axes = std::move(stage.axes);
      d.rotary = std::move(stage.rotary);
      d.gripper = std::move(stage.gripper);
      // The microscope is the slave's: its frames, over DDS (the master has no microworld to image).
      if (cfg.camera.enabled && cfg.devices.camera.driver != "none")
        d.camera = std::make_unique<mc::devices::Camera>(
            "camera", cfg.camera, std::make_unique<mc::net::RemoteCameraSource>(domain, network));
      return d;
    };
  } else {
    mc::net::RemoteMasterParams rp;
    rp.link.domain_id = o.domain;
    rp.link.network = mc::cli::network_config(o.network);
    rp.emulate = o.link;
    rp.passivity = o.passivity == "on";
    rp.home_m = {lp.platform.stage.home_x_m, lp.platform.stage.home_y_m, lp.platform.stage.home_z_m};
    rp.goal_speed_m_s = lp.platform.teleop.console_max_speed_m_s;
    rp.rotary = lp.platform.stage.rotary.enabled && !lp.platform.optical_trap_scene();
    ends.master = std::make_unique<mc::net::RemoteMaster>(rp);
    lp.remote = ends.master.get();
  }
  return ends;
}

// The live platform's focus drive as the microscope topics carry it: where the focal plane is,
// or (`wanted`) where its operator sent it.
mc::net::MicroscopeJoints microscope_joints(const mc::live::LivePlatform& live, bool wanted) {
  const mc::live::LiveStatus st = live.status();
  mc::net::MicroscopeJoints j;
  if (st.ticks == 0) return j;  // the loop has not run: its drive's state is not known yet
  j.has_focus = true;
  j.focus_z_m = wanted ? st.focus_target_m : st.focus_z_m;
  j.objective = st.objective;
  return j;
}

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

bool is_loopback(const std::string& host) {
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

// A token for a server reachable from the network: 128 bits from the kernel's generator.
std::string random_token() {
  std::ifstream in("/dev/urandom", std::ios::binary);
  unsigned char bytes[16];
  if (!in.read(reinterpret_cast<char*>(bytes), sizeof bytes))
    throw mc::InvalidInput("/dev/urandom: cannot read a token; give one with --token");
  std::string t;
  for (unsigned char b : bytes) t += fmt::format("{:02x}", b);
  return t;
}

// `--cell`: one part of a batch (its microworld becomes the scene) and the task the console
// supervises on it, with the task file's autonomy and parameters.
void use_cell(const ServeOptions& o, mc::live::LiveParams& lp) {
  if (o.role != "single") throw mc::UsageError("--cell: runs where the console drives: not with --role");
  mc::cell::AssemblyBatchParams batch;
  if (o.scene) batch = mc::load_params<mc::cell::AssemblyBatchParams>(*o.scene);
  if (o.seed) batch.seed = *o.seed;
  const int part = o.part.value_or(0);
  if (part >= batch.parts)
    throw mc::UsageError("--part " + std::to_string(part) + ": the batch has " + std::to_string(batch.parts) +
                         " parts (0 to " + std::to_string(batch.parts - 1) + ")");
  mc::cli::naming_flags({{"seed", "--seed"}}, [&] { batch.validate(); });
  const std::vector<mc::cell::AssemblyJob> jobs = mc::cell::assembly_jobs(batch);
  const mc::cell::AssemblyJob& job = jobs[static_cast<std::size_t>(part)];
  mc::live::LiveTaskParams tp;
  tp.goal = mc::cell::assembly_goal(job);
  // The whole batch, so that the console's Next part goes through it.
  for (const mc::cell::AssemblyJob& j : jobs)
    tp.parts.push_back({j.index, j.world, mc::cell::assembly_goal(j)});
  tp.part = part;
  if (o.task) {
    const mc::cell::AssemblyTaskFile f = mc::cell::load_task_file(*o.task);
    tp.task = f.params;
    tp.autonomy = f.steps.autonomy();
  }
  tp.camera.enabled = o.cell_camera;
  lp.platform.microworld = "pick-place";
  lp.platform.world = job.world;
  lp.platform.validate();
  lp.task = tp;
  std::string levels;
  for (int i = 0; i + 1 < mc::cell::AssemblyTask::kStepCount; ++i)
    if (tp.autonomy[static_cast<std::size_t>(i)] != mc::cell::AssemblyTask::Autonomy::kAuto)
      levels += fmt::format("{}{} {}", levels.empty() ? "" : ", ",
                            mc::cell::AssemblyTask::name(static_cast<mc::cell::AssemblyTask::Step>(i)),
                            mc::cell::AssemblyTask::name(tp.autonomy[static_cast<std::size_t>(i)]));
  std::cerr << fmt::format(
      "serve: cell part {} of the batch of seed {} ({} parts): a {:.0f} um {} with {:.1f} um of {}{}; steps "
      "{}{}; the task waits for Start in the console (Next part: the batch's next)\n",
      part, batch.seed, batch.parts, 1e6 * job.side_m, job.flat ? "plate onto its seat" : "pin into a bore",
      1e6 * job.clearance_m, job.flat ? "seat tolerance" : "radial clearance",
      job.world.neighbour_count > 0 ? fmt::format(", among {} other parts", job.world.neighbour_count) : "",
      levels.empty() ? "all auto" : levels + " (the rest auto)",
      o.cell_camera ? "; the cell's camera looks" : "");
}

void serve(const ServeOptions& o) {
  mc::live::LiveParams lp;
  if (o.config) lp.platform = pf::load_platform_config(*o.config);
  if (!o.cell && (o.seed || o.part || o.task || o.cell_camera))
    throw mc::UsageError(std::string(o.task          ? "--task"
                                     : o.seed        ? "--seed"
                                     : o.cell_camera ? "--cell-camera"
                                                     : "--part") +
                         ": needs --cell");
  const std::string scene = o.scene.value_or("pick-place");
  if (o.cell) {
    use_cell(o, lp);
  } else if (scene == "pin-in-hole") {
    lp.platform.world = mc::microworld::pin_in_hole_scene();
  } else if (scene == "optical-trap") {
    pf::use_optical_trap_scene(lp.platform);
  } else if (scene != "pick-place") {
    // A scene file: the microworld's keys (part, hole, start, target, adhesion, gripper).
    std::error_code ec;
    if (!std::filesystem::is_regular_file(scene, ec))
      throw mc::InvalidInput(
          "--scene '" + mc::excerpt(scene) +
          "': neither a built-in scene (pick-place, pin-in-hole, optical-trap) nor a "
          "scene file (a YAML file of the microworld's keys, e.g. scenes/pin-in-hole.yaml)");
    lp.platform.world = mc::load_params<mc::microworld::PickPlaceParams>(scene, lp.platform.world);
  }
  auto [host, port] = parse_listen(o.listen);
  mc::live::ConsoleServerParams sp;
  sp.server.address = host;
  sp.server.port = port;
  sp.server.token = o.token;
  if (sp.server.token.empty() && !is_loopback(host)) sp.server.token = random_token();
  if (!sp.server.token.empty() && (sp.server.token.size() < 8 || sp.server.token.size() > 256 ||
                                   sp.server.token.find_first_of(" &#?%/\"'<>") != std::string::npos))
    throw mc::UsageError("--token: must be 8 to 256 characters without spaces or any of &#?%/\"'<>");
  sp.out_dir = o.out;
  sp.record_csv = o.record_csv;
  // Each recording holds the program's version and the configuration it ran (as --print-config
  // prints it: the keys --config takes), so a recording alone says what was run.
  sp.version = std::string("microcobot ") + MC_VERSION;
  sp.config_yaml = mc::params_to_yaml(lp.platform);
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  if (ec) throw mc::InvalidInput("cannot create --out " + mc::excerpt(o.out.string()) + ": " + ec.message());
  if (!std::filesystem::is_directory(o.out, ec))
    throw mc::InvalidInput("--out " + mc::excerpt(o.out.string()) + ": exists and is not a directory");

  std::vector<mc::twins::TwinEndpoint> twins;
  for (const auto& e : o.emulate) twins.push_back(mc::twins::parse_emulate(e));
  std::string twin_token = sp.server.token;
  for (const auto& t : twins)
    if (twin_token.empty() && !is_loopback(t.address)) twin_token = random_token();
  RemoteEnds ends = attach_role(o, lp);
  mc::cli::set_cooperative_interrupts(true);
  std::cerr << "serve: building the platform (the stick-slip step map takes about a second) on "
            << (lp.platform.devices.simulated() ? std::string("the simulated devices")
                                                : "the drivers '" + lp.platform.devices.driver + "' (" +
                                                      lp.platform.devices.connection + ")")
            << "\n";
  if (o.role != "single")
    std::cerr << "serve: " << o.role << " of a distributed platform on DDS domain " << o.domain << " ("
              << mc::cli::describe(mc::cli::network_config(o.network)) << "; the peer: serve --role "
              << (o.role == "master" ? "slave" : "master") << " --domain " << o.domain << ")\n";
  mc::live::LivePlatform live(lp);
  // The slave's camera on DDS as a ROS 2 image topic (declared before the server that calls it).
  std::unique_ptr<mc::net::CameraImagePublisher> images;
  if (o.role == "slave" && live.has_camera())
    images = std::make_unique<mc::net::CameraImagePublisher>(o.domain, mc::cli::network_config(o.network));
  // The microscope's focus and turret on DDS: the slave takes them from any peer, the master
  // sends its operator's (net/microscope_link.h).
  std::unique_ptr<mc::net::MicroscopeServer> microscope_server;
  std::unique_ptr<mc::net::MicroscopeClient> microscope_client;
  if (o.role == "slave" && live.has_camera()) {
    microscope_server = std::make_unique<mc::net::MicroscopeServer>(
        o.domain, mc::cli::network_config(o.network),
        [&live](const mc::net::MicroscopeJoints& j) {
          mc::live::ConsoleCommand c;
          c.has_focus = j.has_focus;
          c.focus_z_m = j.focus_z_m;
          c.objective = j.objective;
          live.push_microscope_command(c);  // a full ring (16 waiting) drops it: the next one counts
        },
        [&live] { return microscope_joints(live, false); });
    std::cerr << "serve: the microscope's focus and objective on DDS, ROS 2 topics "
              << mc::net::kMicroscopeCommandRosName << " and " << mc::net::kMicroscopeStateRosName
              << " (sensor_msgs/msg/JointState)\n";
  }
  if (o.role == "master" && live.has_camera())
    microscope_client = std::make_unique<mc::net::MicroscopeClient>(
        o.domain, mc::cli::network_config(o.network), [&live] { return microscope_joints(live, true); });
  mc::live::ConsoleServer server(live, sp);
  if (images) {
    server.add_frame_consumer(
        {[p = images.get()](const mc::devices::CameraFrame& f, double t_s) { p->publish(f, t_s); },
         [p = images.get()] { return p->wanted(); }});
    std::cerr << "serve: camera images on DDS, ROS 2 topic " << mc::net::kCameraImageRosName << " ("
              << mc::net::kCameraImageTypeName << ")\n";
  }
  server.start();
  // The vendor-protocol twins: their own thread, the live platform reached through its ring.
  std::unique_ptr<mc::twins::LiveStage> twin_stage;
  std::unique_ptr<mc::twins::TwinServer> twin_server;
  if (!twins.empty()) {
    mc::twins::TwinServerParams tp;
    tp.endpoints = twins;
    tp.token = twin_token;
    tp.gcs2.idn = std::string("microcobot, E-873 digital twin, 0, ") + MC_VERSION;
    twin_stage = std::make_unique<mc::twins::LiveStage>(live);
    twin_server = std::make_unique<mc::twins::TwinServer>(*twin_stage, tp);
    twin_server->start();
  }
  if (o.record) server.start_recording();
  // The first line on stdout: what the operator opens; then one line per twin.
  std::cout << server.url() << std::endl;
  for (std::size_t k = 0; k < twins.size(); ++k) {
    const char* name = twins[k].protocol == mc::twins::Protocol::kGcs2 ? "gcs2" : "anc300";
    std::cout << "emulate " << name << " " << twins[k].address << ":" << twin_server->ports()[k] << std::endl;
    std::cerr << "serve: " << name << " twin on " << twins[k].address << ":" << twin_server->ports()[k]
              << (is_loopback(twins[k].address) ? "" : " (token " + twin_token + ")") << "\n";
  }
  std::cerr << "serve: console at " << server.url() << " (Ctrl-C stops: devices to their safe state)\n";
  if (host == "0.0.0.0" || host == "::")
    std::cerr
        << "serve: listening on every interface: from another machine, open this machine's address on port "
        << server.port() << " with the same token\n";
  const auto start = std::chrono::steady_clock::now();
  while (mc::cli::interrupt_signal() == 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (o.duration_s > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= o.duration_s)
      break;
  }
  if (twin_server) twin_server->stop();  // its clients gone: the stage holds
  server.stop();
  mc::cli::set_cooperative_interrupts(false);
  if (ends.slave || ends.master) {
    const double lowest =
        ends.slave ? ends.slave->min_observed_energy_J() : ends.master->min_observed_energy_J();
    const double dissipated =
        ends.slave ? ends.slave->dissipated_energy_J() : ends.master->dissipated_energy_J();
    std::cerr << fmt::format(
        "serve: this end's ports (passivity control {}): lowest observed energy {:.3g} J, {:.3g} J refused\n",
        o.passivity, lowest, dissipated);
  }
  const int sig = mc::cli::interrupt_signal();
  std::cerr << "serve: stopped" << (sig ? " on " + mc::cli::signal_name(sig) : std::string())
            << ": every device in its safe state, recordings closed in " << o.out.string() << "\n";
}

void add_serve(CLI::App& cmd) {
  auto o = std::make_shared<ServeOptions>();
  cmd.add_option("--config", o->config, "Platform configuration (YAML; keys as `run --print-config` shows)");
  cmd.add_option(
      "--scene", o->scene,
      "Scene: pick-place (default: the 300 um part), pin-in-hole (a 200 um pin into a hole with "
      "20 um of clearance), optical-trap (a 3 um bead in optical tweezers, touching a stuck "
      "bead) or a YAML file of the microworld's keys (scenes/*.yaml); with --cell, the batch (YAML; "
      "`cell params` shows its keys under scene)");
  cmd.add_flag("--cell", o->cell,
               "The assembly cell: one part of a batch (--scene, --seed, --part) inserted by the automatic "
               "task, which the console starts, pauses, takes over and hands back (docs/cell.md)");
  cmd.add_option("--seed", o->seed, "With --cell: the batch's seed (default 1)")
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--part", o->part, "With --cell: which part of the batch (default 0)")
      ->check(CLI::Range(0, 9999));
  cmd.add_option(
      "--task", o->task,
      "With --cell: a task file (YAML: `steps` autonomy auto|confirm|manual, `params` of the task; "
      "docs/cell.md)");
  cmd.add_flag("--cell-camera", o->cell_camera,
               "With --cell: the cell's camera looks at the pin in its slot, in the fingers and placed "
               "(rendered frames; the task holds while it looks; docs/cell.md)");
  cmd.add_option("--listen", o->listen,
                 "Address and port (default 127.0.0.1:8080; port 0 picks a free one; any non-loopback "
                 "address requires a token)");
  cmd.add_option("--token", o->token, "Token the WebSocket clients must give (generated off loopback)");
  cmd.add_option(
      "--emulate", o->emulate,
      "Serve a vendor protocol on the live stage (repeatable): gcs2[=ADDR:PORT] (PI GCS 2.0, default "
      "127.0.0.1:50000) or anc300[=ADDR:PORT] (Attocube ANC300 console, default 127.0.0.1:7230); "
      "docs/hardware.md");
  cmd.add_option("--out", o->out, "Directory of the MCAP recordings (default out/live)");
  cmd.add_flag("--record", o->record, "Start recording at once (else from the console)");
  cmd.add_flag("--record-csv", o->record_csv,
               "Also write each recording's telemetry as CSV beside its MCAP file (off: the MCAP file "
               "holds every sample; the console offers the CSV when it exists)");
  cmd.add_option("--duration", o->duration_s,
                 "Stop after this many seconds of wall-clock time (default: never)")
      ->check(mc::cli::Range(0.0, 1e7));
  cmd.add_option("--role", o->role,
                 "single (default: the whole platform here), master (the operator's side: console, masters, "
                 "coupling; the stage is the slave process's) or slave (stage, gripper, microworld, stage "
                 "controller; commands from the master process), joined over DDS (docs/distributed.md)")
      ->check(CLI::IsMember({"single", "master", "slave"}));
  cmd.add_option(
         "--domain", o->domain,
         fmt::format("DDS domain id of the master-slave link, 0 to {} (default 0; both ends the same)",
                     mc::net::kMaxDomainId))
      ->check(CLI::Range(0, mc::net::kMaxDomainId));
  mc::cli::add_network_options(cmd, o->network);
  cmd.add_option("--link-delay", o->link.delay_s,
                 "Emulated one-way delay of what this end receives, s (default 0; both ends: a round trip "
                 "of twice it)")
      ->check(mc::cli::Range(0.0, 10.0));
  cmd.add_option("--link-jitter", o->link.jitter_s,
                 "Emulated jitter, s: each delay uniform in delay +- jitter (default 0; at most the delay)")
      ->check(mc::cli::Range(0.0, 10.0));
  cmd.add_option(
         "--link-loss", o->link.loss,
         "Emulated probability of losing a best-effort sample, [0, 1) (default 0; the reliable e-stop "
         "and engaged topics are only delayed)")
      ->check(mc::cli::Range(0.0, 0.999));
  cmd.add_option("--passivity", o->passivity,
                 "Time-domain passivity control at this end's ports of the master-slave channel: on "
                 "(default; keeps the coupling passive under delay and loss, docs/model.md) or off "
                 "(observed only). Needs --role")
      ->check(CLI::IsMember({"on", "off"}));
  cmd.callback([o] { serve(*o); });
}

const bool kRegistered = mc::cli::register_group(
    {"serve", "Run the platform live: the operator's console in a browser, Foxglove WebSocket, MCAP", 6,
     &add_serve});

}  // namespace
}  // namespace serve_commands

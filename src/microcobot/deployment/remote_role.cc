#include "microcobot/deployment/remote_role.h"

#include <string>

#include "microcobot/core/error.h"
#include "microcobot/devices/camera_device.h"
#include "microcobot/devices/simulated_haptic_master.h"
#include "microcobot/devices/simulated_tweezers_master.h"
#include "microcobot/net/remote_camera.h"
#include "microcobot/net/wire_emulator.h"
#include "microcobot/platform/driver_registry.h"
#include "microcobot/platform/platform_config.h"

namespace mc::deployment {

namespace pf = mc::platform;

RemoteEnds attach_role(const ServeConfig& o, live::LiveParams& lp) {
  RemoteEnds ends;
  if (o.role == Role::kSingle) {
    if (net::impairs(o.link))
      throw UsageError("--link-delay, --link-jitter, --link-loss: need --role master or slave");
    if (o.network) throw UsageError("--interface, --peer: need --role master or slave");
    if (!o.passivity) throw UsageError("--passivity: needs --role master or slave");
    return ends;
  }
  if (o.domain < 0 || o.domain > net::kMaxDomainId)
    throw UsageError("--domain: " + std::to_string(o.domain) + " is out of range: expected 0 to " +
                     std::to_string(net::kMaxDomainId));
  if (o.link.jitter_s > o.link.delay_s)
    throw UsageError(
        "--link-jitter: must not exceed --link-delay (delays are delay +- jitter, never negative)");
  const net::NetworkConfig network = o.network.value_or(net::NetworkConfig{});
  const stickslip::StickSlipParams axis = pf::axis_params(lp.platform);
  if (o.role == Role::kMaster) {
    net::RemoteSlaveParams rp;
    rp.link.domain_id = o.domain;
    rp.link.network = network;
    rp.emulate = o.link;
    rp.passivity = o.passivity;
    rp.sample_period_s = axis.integrator.dt_s;
    rp.max_voltage_V = axis.drive.max_V;
    rp.rotary = lp.platform.stage.rotary;  // the slave's rotary axis (the same configuration)
    rp.rotary.enabled = rp.rotary.enabled && !lp.platform.optical_trap_scene();
    ends.slave = std::make_unique<net::RemoteSlave>(rp);
    // The masters are this machine's (simulated, the operator then uses the console, or the
    // drivers' masters: their stage and gripper, built but never configured, are not opened);
    // the stage is the slave process's.
    lp.make_devices = [remote = ends.slave.get(), cfg = lp.platform, domain = o.domain, network] {
      devices::DeviceSet d;
      if (cfg.devices.simulated()) {
        d.haptic = std::make_unique<devices::SimulatedHapticMaster>(
            "dual_stage", cfg.haptic.plant, cfg.haptic.render, cfg.haptic.pantograph, cfg.loop.period_s());
        d.tweezers = std::make_unique<devices::SimulatedTweezersMaster>("teletweez", cfg.tweezers,
                                                                        cfg.loop.period_s());
      } else {
        d = pf::make_driver_devices(cfg);
      }
      devices::DeviceSet stage = remote->make_devices();
      d.axes = std::move(stage.axes);
      d.rotary = std::move(stage.rotary);
      d.gripper = std::move(stage.gripper);
      // The microscope is the slave's: its frames, over DDS (the master has no microworld to image).
      if (cfg.camera.enabled && cfg.devices.camera.driver != "none")
        d.camera = std::make_unique<devices::Camera>(
            "camera", cfg.camera, std::make_unique<net::RemoteCameraSource>(domain, network));
      return d;
    };
  } else {
    net::RemoteMasterParams rp;
    rp.link.domain_id = o.domain;
    rp.link.network = network;
    rp.emulate = o.link;
    rp.passivity = o.passivity;
    rp.home_m = {lp.platform.stage.home_x_m, lp.platform.stage.home_y_m, lp.platform.stage.home_z_m};
    rp.goal_speed_m_s = lp.platform.teleop.console_max_speed_m_s;
    rp.rotary = lp.platform.stage.rotary.enabled && !lp.platform.optical_trap_scene();
    ends.master = std::make_unique<net::RemoteMaster>(rp);
    lp.remote = ends.master.get();
  }
  return ends;
}

net::MicroscopeJoints microscope_joints(const live::LivePlatform& live, bool wanted) {
  const live::LiveStatus st = live.status();
  net::MicroscopeJoints j;
  if (st.ticks == 0) return j;  // the loop has not run: its drive's state is not known yet
  j.has_focus = true;
  j.focus_z_m = wanted ? st.focus_target_m : st.focus_z_m;
  j.objective = st.objective;
  return j;
}

}  // namespace mc::deployment

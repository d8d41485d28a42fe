#include "microcobot/platform/platform_config.h"

#include <cmath>
#include <functional>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/core/params.h"
#include "microcobot/platform/driver_registry.h"
#include "microcobot/runtime/cpu_affinity.h"

namespace mc::platform {
namespace {

// Runs a section's validate() and prefixes the section's key path to the field it names.
void in_section(const std::string& section, const std::function<void()>& validate) {
  try {
    validate();
  } catch (const InvalidParams& e) {
    const std::string what = e.what();
    const std::string head = "invalid parameter ";
    const std::string rest = what.rfind(head, 0) == 0 ? what.substr(head.size()) : what;
    throw Error(ExitCode::kInvalidInput, head + section + "." + rest);
  }
}

// The pick-and-place scene must lie within the stage's reach: the tool is at home + the axes'
// positions, and each axis travels within +-stroke/2 (a home 1 m away on a 12 mm stroke could only
// time out). `stroke_m` is the axes' (StickSlipParams::slider).
void check_reach(const PlatformConfig& c, double stroke_m) {
  if (c.microworld != "pick-place") return;
  const double half = 0.5 * stroke_m;
  const auto reach = [&](double home, const char* home_key, double point, const std::string& point_key) {
    require(std::abs(point - home) < half, std::string("stage.") + home_key,
            fmt::format("puts {} = {:g} m out of the stage's reach: the axes travel +-{:g} m (half their "
                        "stroke_m) around the home",
                        point_key, point, half),
            home);
  };
  const auto& w = c.world;
  reach(c.stage.home_x_m, "home_x_m", w.part_start_m.x(), "world.part_start_x_m");
  reach(c.stage.home_y_m, "home_y_m", w.part_start_m.y(), "world.part_start_y_m");
  reach(c.stage.home_x_m, "home_x_m", w.target_m.x(), "world.target_x_m");
  reach(c.stage.home_y_m, "home_y_m", w.target_m.y(), "world.target_y_m");
  reach(c.stage.home_z_m, "home_z_m", 0.5 * w.height_m(), "the part's mid-height");
}

}  // namespace

void LoopParams::validate() const {
  require_positive(base_rate_Hz, "base_rate_Hz");
  require(slave_divisor >= 1, "slave_divisor", "must be >= 1", slave_divisor);
  require(operator_divisor >= 1, "operator_divisor", "must be >= 1", operator_divisor);
  require(telemetry_divisor >= 1, "telemetry_divisor", "must be >= 1", telemetry_divisor);
  require(watchdog_ticks >= 1, "watchdog_ticks", "must be >= 1", watchdog_ticks);
  require(cpu == -1 || runtime::core_allowed(cpu), "cpu",
          "must be -1 (not pinned) or a core this process may use (" + runtime::allowed_cores() + ")", cpu);
}

void PlatformConfig::validate() const {
  in_section("devices", [&] {
    if (devices.gripper != "driver" && devices.gripper != "simulated")
      throw InvalidParams("gripper", "'" + excerpt(devices.gripper) + "' is not driver or simulated");
    if (devices.gripper == "simulated" && !devices.simulated() && optical_trap_scene())
      throw InvalidParams("gripper", "simulated needs the pick-place microworld (microworld: optical-trap)");
  });
  in_section("devices", [&] {
    if (is_device_driver(devices.driver)) return;
    std::string known;
    for (const std::string& n : device_driver_names()) known += (known.empty() ? "" : ", ") + n;
    throw InvalidParams(
        "driver", "'" + excerpt(devices.driver) + "' is not a registered driver (known: " + known + ")");
  });
  in_section("devices.camera", [&] {
    if (is_camera_driver(devices.camera.driver)) return;
    std::string known;
    for (const std::string& n : camera_driver_names()) known += (known.empty() ? "" : ", ") + n;
    throw InvalidParams("driver", "'" + excerpt(devices.camera.driver) +
                                      "' is not a camera driver of this build (known: " + known + ")");
  });
  alignment.validate();  // its errors name alignment.*
  in_section("camera", [&] { camera.validate(); });
  in_section("vision_force", [&] { vision_force.validate(); });
  in_section("loop", [&] { loop.validate(); });
  in_section("teleop", [&] { teleop.validate(); });
  in_section("stage", [&] {
    stage.control.validate();
    stage.sensor.validate();
    stage.step_map.validate();
    require(std::isfinite(stage.home_x_m) && std::isfinite(stage.home_y_m) && std::isfinite(stage.home_z_m),
            "home_m", "must be finite");
    if (stage.xy_sensor != "encoders" && stage.xy_sensor != "vision")
      throw InvalidParams("xy_sensor", "'" + excerpt(stage.xy_sensor) + "' is not encoders or vision");
    require(std::isfinite(stage.park_after_s) && stage.park_after_s >= 0.0 && stage.park_after_s <= 60.0,
            "park_after_s", "must be within [0, 60] s", stage.park_after_s);
    require(std::isfinite(stage.park_tolerance_m) && stage.park_tolerance_m > 0.0 &&
                stage.park_tolerance_m <= 1e-6,
            "park_tolerance_m", "must be within (0, 1 um]", stage.park_tolerance_m);
    if (stage.vision_xy() && !camera.enabled)
      throw InvalidParams("xy_sensor", "vision needs the camera (camera.enabled: true)");
  });
  in_section("stage.vision", [&] { stage.vision.validate(); });
  in_section("stage.rotary", [&] { stage.rotary.validate(); });
  in_section("stage.control", [&] {
    require(std::abs(stage.control.control_rate_Hz - loop.slave_rate_Hz()) <= 1e-9 * loop.slave_rate_Hz(),
            "control_rate_Hz", "must equal loop.base_rate_Hz / loop.slave_divisor",
            stage.control.control_rate_Hz);
  });
  in_section("stage.tracking", [&] {
    stage.tracking.validate();
    if (!stage.tracking_enabled) return;
    const double f = stage.tracking.control_rate_Hz;
    require(std::abs(f - loop.slave_rate_Hz()) <= 1e-9 * loop.slave_rate_Hz() ||
                std::abs(f - loop.base_rate_Hz) <= 1e-9 * loop.base_rate_Hz,
            "control_rate_Hz", "must equal loop.base_rate_Hz (updated every loop tick) or the slave rate", f);
  });
  in_section("haptic", [&] {
    haptic.plant.validate();
    haptic.render.validate();
    haptic.pantograph.validate();
  });
  in_section("haptic.plant", [&] {
    require(std::abs(haptic.plant.dt_s * loop.base_rate_Hz - 1.0) < 1e-9, "dt_s",
            "must equal 1 / loop.base_rate_Hz", haptic.plant.dt_s);
  });
  in_section("haptic.render", [&] {
    require(std::abs(haptic.render.fs_Hz - loop.base_rate_Hz) <= 1e-9 * loop.base_rate_Hz, "fs_Hz",
            "must equal loop.base_rate_Hz", haptic.render.fs_Hz);
  });
  in_section("tweezers", [&] { tweezers.validate(); });
  in_section("world", [&] { world.validate(); });
  require(microworld == "pick-place" || microworld == "optical-trap", "microworld",
          "must be pick-place or optical-trap, not '" + excerpt(microworld) + "'");
  // The axes' stroke: the default axis, or its file once its path is resolved (a relative path is
  // resolved, and the reach checked, by load_platform_config()).
  if (stickslip_params_file.empty()) {
    check_reach(*this, stickslip::StickSlipParams{}.slider.stroke_m);
  } else if (std::filesystem::path(stickslip_params_file).is_absolute()) {
    check_reach(*this, axis_params(*this).slider.stroke_m);
  }
  require(positioner == "cartesian" || positioner == "parallel", "positioner",
          "must be cartesian or parallel, not '" + excerpt(positioner) + "'");
  require(master_drives == "stage" || master_drives == "positioner", "master_drives",
          "must be stage or positioner, not '" + excerpt(master_drives) + "'");
  require(!master_drives_positioner() || parallel_positioner_enabled(), "master_drives",
          "must be stage with positioner: cartesian (there is no parallel positioner to drive)");
  in_section("parallel_positioner", [&] {
    parallel_positioner.validate();
    const std::string& where = parallel_positioner.controller;
    require(where == "auto" || where == "loop" || where == "thread", "controller",
            "must be auto, loop or thread, not '" + excerpt(where) + "'");
    if (!is_positioner_driver(parallel_positioner.driver)) {
      std::string known;
      for (const std::string& n : positioner_driver_names()) known += (known.empty() ? "" : ", ") + n;
      throw InvalidParams("driver", "'" + excerpt(parallel_positioner.driver) +
                                        "' is not a registered positioner driver (known: " + known + ")");
    }
    if (!parallel_positioner_enabled()) return;
    // One loop tick is a whole number of the legs' control periods (the device ticks them).
    const double n = parallel_positioner.tracking.control_rate_Hz / loop.base_rate_Hz;
    require(n >= 1.0 - 1e-9 && std::abs(n - std::round(n)) < 1e-6 * n, "tracking.control_rate_Hz",
            "must be a whole multiple of loop.base_rate_Hz", parallel_positioner.tracking.control_rate_Hz);
  });
  in_section("parallel_positioner.controller_thread",
             [&] { parallel_positioner.controller_thread.validate(); });
  in_section("optical_trap", [&] {
    optical_trap.validate();
    const double ratio = loop.period_s() / optical_trap.trap.dt_s;
    require(ratio >= 1.0 && std::abs(ratio - std::round(ratio)) < 1e-6 * ratio, "dt_s",
            "must divide the loop period (1 / loop.base_rate_Hz)", optical_trap.trap.dt_s);
  });
}

void use_optical_trap_scene(PlatformConfig& config) {
  config.microworld = "optical-trap";
  config.teleop.motion_scale = 5e-4;
  config.teleop.force_scale = 1e10;
  config.teleop.force_filter_Hz = 1000.0;
  config.teleop.console_max_speed_m_s = 20e-6;
  config.stage.tracking_enabled = false;
  // The camera on the beads: the turret's strongest objective (the 3 um probe bead ~ 28 px at
  // 50x), centred on the trap's home, focused on the dish plane where both beads lie.
  config.camera.objective = static_cast<int>(config.camera.objectives.size()) - 1;
  config.camera.view_center_x_m = config.stage.home_x_m;
  config.camera.view_center_y_m = config.stage.home_y_m;
  config.camera.focus_start_m = config.optical_trap.trap.bead_radius_m;
}

PlatformConfig load_platform_config(const std::filesystem::path& file) {
  PlatformConfig c;
  c = load_params(file, c);
  if (!c.stickslip_params_file.empty()) {
    const std::filesystem::path p(c.stickslip_params_file);
    if (p.is_relative()) c.stickslip_params_file = (file.parent_path() / p).string();
    check_reach(c, axis_params(c).slider.stroke_m);  // read now: a bad axis file is a configuration error
  }
  return c;
}

stickslip::StickSlipParams axis_params(const PlatformConfig& config) {
  if (config.stickslip_params_file.empty()) return stickslip::StickSlipParams{};
  return load_params<stickslip::StickSlipParams>(config.stickslip_params_file);
}

perception::CameraRig camera_rig(const PlatformConfig& config) {
  perception::CameraRig rig;
  rig.camera = config.camera;
  rig.stage_home_m = {config.stage.home_x_m, config.stage.home_y_m};
  rig.finger_width_m = config.world.gripper.finger_width_m;
  rig.finger_stiffness_N_m = config.world.gripper.finger_stiffness_N_m;
  return rig;
}

}  // namespace mc::platform

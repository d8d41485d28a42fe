// The platform's telemetry: the built-in channels, each declared with the function that reads
// it off the platform, the channels added by a caller, and the loop task that samples them.
#include <vector>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/motion/pose.h"
#include "microcobot/platform/platform.h"
#include "microcobot/platform/telemetry_schema.h"

namespace mc::platform {

struct Platform::BuiltinChannel {
  const char* name;
  const char* unit;
  const char* description;
  double (*source)(const Platform&) noexcept;
};

double Platform::axis_voltage_V(std::size_t i) const noexcept {
  if (faulted_) return 0.0;
  // An open-loop run (and the axes positioned by vision, which move only by such runs) drives
  // the axis from its stepper; otherwise the stage controller does.
  const bool stepped = steppers_[i]->running() || (vision_xy_ && i < 2);
  return stepped ? steppers_[i]->output_V() : stage_->last_voltage_V(static_cast<int>(i));
}

// The loop channels come first: what the loop itself sees on any devices (the devices'
// interfaces, the coupling, the controller's commands). Positions are in the world frame (the
// stage's home added to the axes' own).
std::span<const Platform::BuiltinChannel> Platform::loop_channels() {
  using P = const Platform&;
  static constexpr BuiltinChannel kChannels[] = {
      {"t_s", "s", "time since the loop started", [](P p) noexcept { return p.loop_.time_s(); }},
      {"handle_x_m", "m", "the haptic master's handle position, x",
       [](P p) noexcept { return p.devices_.haptic->handle_position_m().x; }},
      {"handle_y_m", "m", "the haptic master's handle position, y",
       [](P p) noexcept { return p.devices_.haptic->handle_position_m().y; }},
      {"deadman", "", "1 while the haptic master's deadman is held",
       [](P p) noexcept { return p.devices_.haptic->enabled() ? 1.0 : 0.0; }},
      {"clutch", "", "1 while the haptic master's clutch is pressed (the handle moves alone)",
       [](P p) noexcept { return p.devices_.haptic->clutch() ? 1.0 : 0.0; }},
      {"engaged", "", "1 while the coupling drives the slave",
       [](P p) noexcept { return p.teleop_->output().engaged ? 1.0 : 0.0; }},
      {"stale", "", "1 while a master's or the slave's readings are stale (the slave holds)",
       [](P p) noexcept { return p.teleop_->output().stale ? 1.0 : 0.0; }},
      {"target_x_m", "m", "the slave's target, x",
       [](P p) noexcept { return p.home_m_.x() + p.teleop_->output().slave_target_m.x(); }},
      {"target_y_m", "m", "the slave's target, y",
       [](P p) noexcept { return p.home_m_.y() + p.teleop_->output().slave_target_m.y(); }},
      {"target_z_m", "m", "the slave's target, z",
       [](P p) noexcept { return p.home_m_.z() + p.teleop_->output().slave_target_m.z(); }},
      {"measured_x_m", "m", "the slave's position as its sensor measures it, x",
       [](P p) noexcept { return p.home_m_.x() + p.devices_.axes[0]->position_m(); }},
      {"measured_y_m", "m", "the slave's position as its sensor measures it, y",
       [](P p) noexcept { return p.home_m_.y() + p.devices_.axes[1]->position_m(); }},
      {"measured_z_m", "m", "the slave's position as its sensor measures it, z",
       [](P p) noexcept { return p.home_m_.z() + p.devices_.axes[2]->position_m(); }},
      {"u_x_V", "V", "the drive voltage of axis x", [](P p) noexcept { return p.axis_voltage_V(0); }},
      {"u_y_V", "V", "the drive voltage of axis y", [](P p) noexcept { return p.axis_voltage_V(1); }},
      {"u_z_V", "V", "the drive voltage of axis z", [](P p) noexcept { return p.axis_voltage_V(2); }},
      {"haptic_force_x_N", "N", "the force commanded to the haptic master, x",
       [](P p) noexcept { return p.teleop_->output().haptic_force_N.x(); }},
      {"haptic_force_y_N", "N", "the force commanded to the haptic master, y",
       [](P p) noexcept { return p.teleop_->output().haptic_force_N.y(); }},
      {"tweezers_opening_m", "m", "the TeleTweez's opening (the operator's fingers)",
       [](P p) noexcept { return p.devices_.tweezers->opening_m(); }},
      {"finger_force_N", "N", "the grip force the TeleTweez renders to the operator's fingers",
       [](P p) noexcept { return p.teleop_->output().finger_force_N; }},
      {"gripper_command_m", "m", "the opening commanded to the micro-gripper",
       [](P p) noexcept { return p.teleop_->output().gripper_opening_m; }},
      {"gripper_opening_m", "m", "the micro-gripper's opening as it measures it",
       [](P p) noexcept { return p.devices_.gripper->opening_m(); }},
      {"grip_force_N", "N", "the grip force on the part as the gripper measures it",
       [](P p) noexcept { return p.devices_.gripper->grip_force_N(); }},
      {"contact_x_N", "N", "the contact force on the tool, x",
       [](P p) noexcept { return p.devices_.gripper->contact_force_N().x; }},
      {"contact_y_N", "N", "the contact force on the tool, y",
       [](P p) noexcept { return p.devices_.gripper->contact_force_N().y; }},
      {"contact_z_N", "N", "the contact force on the tool, z",
       [](P p) noexcept { return p.devices_.gripper->contact_force_N().z; }},
      {"target_theta_rad", "rad", "the rotary axis' target (0 without the axis)",
       [](P p) noexcept { return p.has_rotary() ? p.yaw_target_rad() : 0.0; }},
      {"measured_theta_rad", "rad", "the rotary axis' measured angle (0 without the axis)",
       [](P p) noexcept { return p.has_rotary() ? p.yaw_rad() : 0.0; }},
      {"u_theta_V", "V", "the rotary axis' drive voltage (0 without the axis)",
       [](P p) noexcept { return p.has_rotary() ? p.axis_voltage_V(3) : 0.0; }},
      // The last tick where the telemetry task ran with the others (slave control, telemetry:
      // the heaviest), one sample late: this tick is not over yet.
      {"tick_us", "us", "the wall time of the last sampled loop tick",
       [](P p) noexcept { return 1e6 * p.loop_.sampled_tick_s(); }},
      {"tick_cpu_us", "us", "the CPU time of the last sampled loop tick",
       [](P p) noexcept { return 1e6 * p.loop_.sampled_tick_cpu_s(); }},
  };
  return kChannels;
}

// The simulation's ground truth, recorded when records_simulation(): on a driver's stage with
// a simulated microworld the tips are where the stage's sensors say. In the optical-trap scene
// the part channels are the probe bead's (part_phase, the yaws and shaking 0).
std::span<const Platform::BuiltinChannel> Platform::simulation_channels() {
  using P = const Platform&;
  static constexpr BuiltinChannel kChannels[] = {
      {"hand_x_m", "m", "the simulated operator's hand, x",
       [](P p) noexcept { return p.sim_.haptic->operator_hand().hand_m.x; }},
      {"hand_y_m", "m", "the simulated operator's hand, y",
       [](P p) noexcept { return p.sim_.haptic->operator_hand().hand_m.y; }},
      {"slave_x_m", "m", "the tool's true position, x (the carriage, not its sensor)",
       [](P p) noexcept { return p.home_m_.x() + p.devices_.axes[0]->carried_position_m(); }},
      {"slave_y_m", "m", "the tool's true position, y (the carriage, not its sensor)",
       [](P p) noexcept { return p.home_m_.y() + p.devices_.axes[1]->carried_position_m(); }},
      {"slave_z_m", "m", "the tool's true position, z (the carriage, not its sensor)",
       [](P p) noexcept { return p.home_m_.z() + p.devices_.axes[2]->carried_position_m(); }},
      {"pantograph_y_N", "N", "the dual-stage master's low-frequency force (the pantograph)",
       [](P p) noexcept { return p.sim_.haptic->channels().f_m_N; }},
      {"haptuator_V", "V", "the dual-stage master's high-frequency drive (the haptuator)",
       [](P p) noexcept { return p.sim_.haptic->channels().u_V; }},
      {"part_x_m", "m", "the part's position, x (the probe bead's in the optical trap)",
       [](P p) noexcept { return p.simulated_part_m().x(); }},
      {"part_y_m", "m", "the part's position, y (the probe bead's in the optical trap)",
       [](P p) noexcept { return p.simulated_part_m().y(); }},
      {"part_z_m", "m", "the part's position, z (the probe bead's in the optical trap)",
       [](P p) noexcept { return p.simulated_part_m().z(); }},
      {"part_phase", "", "the part's phase index (microworld::PartPhase; 0 in the optical trap)",
       [](P p) noexcept {
         return p.sim_.gripper ? static_cast<double>(static_cast<int>(p.sim_.gripper->world_state().phase))
                               : 0.0;
       }},
      {"slave_theta_rad", "rad", "the gripper's true yaw (0 in the optical trap)",
       [](P p) noexcept { return p.sim_.gripper ? p.sim_.gripper->yaw_rad() : 0.0; }},
      {"part_yaw_rad", "rad", "the part's yaw (0 in the optical trap)",
       [](P p) noexcept { return p.sim_.gripper ? p.sim_.gripper->part_yaw_rad() : 0.0; }},
      {"gripper_shaking", "", "1 while the gripper's release burst shakes its fingers",
       [](P p) noexcept {
         return p.sim_.gripper && p.sim_.gripper->world_state().gripper.shaking ? 1.0 : 0.0;
       }},
  };
  return kChannels;
}

// The parallel positioner's pose (`positioner: parallel`), after the loop's and the simulation's
// channels: the platform frame {P} in the base frame {H} (motion/pose.h), its origin's position and
// the SmarPod angles of its rotation, R = Rz(rz) Ry(ry) Rx(rx), pivot at {P}'s origin.
std::span<const Platform::BuiltinChannel> Platform::positioner_channels() {
  using P = const Platform&;
  static constexpr BuiltinChannel kChannels[] = {
      {"positioner_x_m", "m", "the parallel positioner's measured pose (FK of its legs' sensors), x",
       [](P p) noexcept { return p.devices_.positioner->measured_pose().d.x(); }},
      {"positioner_y_m", "m", "the parallel positioner's measured pose, y",
       [](P p) noexcept { return p.devices_.positioner->measured_pose().d.y(); }},
      {"positioner_z_m", "m", "the parallel positioner's measured pose, z",
       [](P p) noexcept { return p.devices_.positioner->measured_pose().d.z(); }},
      {"positioner_rx_rad", "rad", "the parallel positioner's measured pose, rx (R = Rz Ry Rx)",
       [](P p) noexcept { return motion::smarpod_angles(p.devices_.positioner->measured_pose().R).x(); }},
      {"positioner_ry_rad", "rad", "the parallel positioner's measured pose, ry",
       [](P p) noexcept { return motion::smarpod_angles(p.devices_.positioner->measured_pose().R).y(); }},
      {"positioner_rz_rad", "rad", "the parallel positioner's measured pose, rz",
       [](P p) noexcept { return motion::smarpod_angles(p.devices_.positioner->measured_pose().R).z(); }},
      {"positioner_moving", "", "1 while a pose move of the parallel positioner runs",
       [](P p) noexcept { return p.devices_.positioner->moving() ? 1.0 : 0.0; }},
      {"positioner_u_max_V", "V", "the largest drive voltage over the parallel positioner's six legs",
       [](P p) noexcept { return p.devices_.positioner->max_leg_voltage_V(); }},
  };
  return kChannels;
}

// The simulated positioner's true pose: FK of its sliders' true positions.
std::span<const Platform::BuiltinChannel> Platform::positioner_truth_channels() {
  using P = const Platform&;
  static constexpr BuiltinChannel kChannels[] = {
      {"positioner_true_x_m", "m", "the parallel positioner's true pose (its sliders, not its sensors), x",
       [](P p) noexcept { return p.sim_.positioner->true_pose().d.x(); }},
      {"positioner_true_y_m", "m", "the parallel positioner's true pose, y",
       [](P p) noexcept { return p.sim_.positioner->true_pose().d.y(); }},
      {"positioner_true_z_m", "m", "the parallel positioner's true pose, z",
       [](P p) noexcept { return p.sim_.positioner->true_pose().d.z(); }},
      {"positioner_true_rx_rad", "rad", "the parallel positioner's true pose, rx",
       [](P p) noexcept { return motion::smarpod_angles(p.sim_.positioner->true_pose().R).x(); }},
      {"positioner_true_ry_rad", "rad", "the parallel positioner's true pose, ry",
       [](P p) noexcept { return motion::smarpod_angles(p.sim_.positioner->true_pose().R).y(); }},
      {"positioner_true_rz_rad", "rad", "the parallel positioner's true pose, rz",
       [](P p) noexcept { return motion::smarpod_angles(p.sim_.positioner->true_pose().R).z(); }},
  };
  return kChannels;
}

Eigen::Vector3d Platform::simulated_part_m() const noexcept {
  if (sim_.gripper != nullptr) return sim_.gripper->part_position_m();
  if (sim_.optical_tweezers != nullptr) return sim_.optical_tweezers->bead_m();
  return Eigen::Vector3d::Zero();
}

const TelemetrySchema& builtin_telemetry(bool simulation) {
  auto schema_of = [](bool with_simulation) {
    TelemetrySchema s;
    for (const auto& c : Platform::loop_channels()) s.add({c.name, c.unit, c.description});
    if (with_simulation)
      for (const auto& c : Platform::simulation_channels()) s.add({c.name, c.unit, c.description});
    return s;
  };
  static const TelemetrySchema loop = schema_of(false);
  static const TelemetrySchema all = schema_of(true);
  return simulation ? all : loop;
}

std::size_t loop_channel_count() { return builtin_telemetry(false).size(); }

void Platform::build_telemetry() {
  telemetry_ = builtin_telemetry(records_simulation());
  telemetry_sources_.clear();
  for (const auto& c : loop_channels()) telemetry_sources_.emplace_back(c.source);
  if (records_simulation())
    for (const auto& c : simulation_channels()) telemetry_sources_.emplace_back(c.source);
  auto add = [this](std::span<const BuiltinChannel> channels) {
    for (const auto& c : channels) {
      telemetry_.add({c.name, c.unit, c.description});
      telemetry_sources_.emplace_back(c.source);
    }
  };
  if (has_positioner()) add(positioner_channels());
  if (sim_.positioner != nullptr) add(positioner_truth_channels());
  recorder_ = std::make_unique<Recorder>(telemetry_.names(), 1);
}

std::size_t Platform::add_telemetry_channel(TelemetryChannel channel, TelemetrySource source) {
  require(static_cast<bool>(source), "telemetry channel '" + excerpt(channel.name) + "'", "needs a source");
  require(loop_.ticks() == 0, "telemetry channel '" + excerpt(channel.name) + "'",
          "must be added before the platform runs");
  const std::size_t i = telemetry_.add(std::move(channel));
  telemetry_sources_.push_back(std::move(source));
  recorder_ = std::make_unique<Recorder>(telemetry_.names(), 1);
  return i;
}

void Platform::telemetry_task() noexcept {
  TelemetrySample s{};  // zero past this platform's channels
  const std::size_t n = telemetry_sources_.size();
  for (std::size_t i = 0; i < n; ++i) s[i] = telemetry_sources_[i](*this);
  ring_.push(s);
}

}  // namespace mc::platform

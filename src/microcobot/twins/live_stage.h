#pragma once
/// @file
/// The live platform as a protocol twin's stage: reads the loop's protocol view
/// (atomics), pushes checked and clamped commands into its protocol ring, and keeps who controls
/// the stage (twins/twin_stage.h), the rotary axis with the three when the platform has it.
/// Protocol thread only: it is the ring's single producer.

#include <optional>

#include "microcobot/live/live_platform.h"
#include "microcobot/twins/twin_stage.h"

namespace mc::twins {

class LiveStage : public TwinStage {
 public:
  /// `live` must outlive this; its limits give the workspace and the speed cap.
  explicit LiveStage(live::LivePlatform& live);

  int axis_count() const override { return axis_count_; }
  Axis axis(int i) const override;
  double min(int i) const override { return min_[static_cast<std::size_t>(i)]; }
  double max(int i) const override { return max_[static_cast<std::size_t>(i)]; }
  double max_speed(int i) const override { return i == kTheta ? max_theta_speed_rad_s_ : max_speed_m_s_; }
  double max_voltage_V() const override { return max_voltage_V_; }
  bool halted() const override;
  bool controls(ClientId client) const override;
  Refusal move_to(ClientId client, const Goal& goal, double speed_m_s, double theta_speed_rad_s) override;
  Refusal step(ClientId client, int i, double amplitude_V, double frequency_Hz, int direction,
               std::int64_t periods) override;
  void stop(ClientId client) override;
  void release(ClientId client) override;
  void heartbeat() override;
  const motion::ParallelKinematics* positioner_kinematics() const override {
    return kinematics_ ? &*kinematics_ : nullptr;
  }
  motion::PoseMoveLimits positioner_limits() const override {
    return live_.params().platform.parallel_positioner.move;
  }
  Refusal move_pose(ClientId client, const motion::PoseTrajectory& traj, std::uint64_t& seq,
                    std::string& reason) override;
  Refusal stop_pose(ClientId client, std::uint64_t& seq) override;
  live::PositionerView positioner_view() override { return live_.positioner_view(); }

 private:
  Refusal claim(ClientId client);
  bool push(live::ProtocolCommand c);

  live::LivePlatform& live_;
  int axis_count_ = 3;
  std::array<double, kMaxAxes> min_{}, max_{};
  double max_speed_m_s_ = 0.0, max_theta_speed_rad_s_ = 0.0, max_voltage_V_ = 0.0;
  double home_rad_ = 0.0;                                 // theta's home: the gripper's yaw at the axis' 0
  std::optional<motion::ParallelKinematics> kinematics_;  // the platform's positioner's geometry
  ClientId owner_ = 0;
  std::uint64_t seq_ = 0;
  std::uint64_t move_seq_ = 0;                      // the last goal's command
  std::array<std::uint64_t, kMaxAxes> step_seq_{};  // each axis' last open-loop run's command
};

}  // namespace mc::twins

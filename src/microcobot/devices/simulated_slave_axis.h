#pragma once
/// @file
/// A slave axis backed by the stick-slip actuator model (thesis ch. 2) and a position
/// sensor model: the digital twin behind the SlaveAxis interface. update() plays the drive
/// samples of the tick through the model at its own step (10 us), so one 10 kHz tick is ten
/// model steps. The safe state holds the drive at 0 V. A diverged model faults the axis.

#include "microcobot/devices/device.h"
#include "microcobot/motion/position_sensor.h"
#include "microcobot/stickslip/actuator.h"

namespace mc::devices {

class SimulatedSlaveAxis final : public SlaveAxis {
 public:
  /// `model` must outlive the axis (one model serves every axis). `start_m` is the carriage's
  /// position at configure() (at rest).
  SimulatedSlaveAxis(std::string name, const stickslip::ActuatorModel& model,
                     const motion::PositionSensorParams& sensor, double start_m);

  double sample_period_s() const override { return model_.dt_s(); }
  double max_voltage_V() const override { return model_.params().drive.max_V; }
  void command_drive(const DriveBlock& block) noexcept override;
  double position_m() const override { return measured_m_; }
  bool at_end_stop() const override;
  void update(double dt_s) noexcept override;
  void enter_safe_state() noexcept override;

  /// The model's true carriage position (what the simulation knows and a sensor approximates).
  double true_position_m() const { return model_.slider_position(state_); }
  double carried_position_m() const override { return true_position_m(); }
  double voltage_V() const { return state_.u_V; }
  const stickslip::ActuatorState& model_state() const { return state_; }

 protected:
  void on_configure() override;

 private:
  const stickslip::ActuatorModel& model_;
  motion::PositionSensor sensor_;
  double start_m_;
  stickslip::ActuatorState state_;
  DriveBlock block_{};
  double measured_m_ = 0.0;
};

}  // namespace mc::devices

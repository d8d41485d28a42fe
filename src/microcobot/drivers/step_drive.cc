#include "microcobot/drivers/step_drive.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/stickslip/actuator.h"

namespace mc::drivers {

void StepDriveParams::validate(std::string_view controller, double max_voltage_V,
                               double max_frequency_Hz) const {
  require(std::isfinite(voltage_V) && voltage_V > 0 && voltage_V <= max_voltage_V,
          "devices.connection option voltage_V",
          fmt::format("must be within (0, {:g}] V (the {}'s range)", max_voltage_V, controller), voltage_V);
  require(std::isfinite(frequency_Hz) && frequency_Hz >= 1 && frequency_Hz <= max_frequency_Hz,
          "devices.connection option frequency_Hz",
          fmt::format("must be within [1, {:g}] Hz", max_frequency_Hz), frequency_Hz);
  require(std::isfinite(max_run_s) && max_run_s >= 1.0 / frequency_Hz && max_run_s <= 1.0,
          "devices.connection option max_run_s", "must be within [1/frequency_Hz, 1] s", max_run_s);
  require(std::isfinite(deadband_m) && deadband_m >= 0 && deadband_m < 1e-4,
          "devices.connection option deadband_nm", "must be within [0, 100000) nm (0: half a step)",
          deadband_m * 1e9);
  require(std::isfinite(step_up_m) && step_up_m > 0 && step_up_m < 1e-5, "step_up_nm",
          "must be within (0, 10000) nm (or left to the model)", step_up_m * 1e9);
  require(std::isfinite(step_down_m) && step_down_m > 0 && step_down_m < 1e-5, "step_down_nm",
          "must be within (0, 10000) nm (or left to the model)", step_down_m * 1e9);
}

long long StepDriveParams::max_periods() const noexcept {
  return std::max(1LL, static_cast<long long>(frequency_Hz * max_run_s));
}

long long StepDriveParams::periods_toward(double error_m) const noexcept {
  const double s = error_m >= 0.0 ? step_up_m : step_down_m;
  const double band = deadband_m > 0.0 ? deadband_m : 0.5 * s;
  if (!std::isfinite(error_m) || std::abs(error_m) <= band) return 0;
  const long long n = std::min(std::max(1LL, std::llround(std::abs(error_m) / s)), max_periods());
  return error_m >= 0.0 ? n : -n;
}

double StepDriveParams::displacement_m(long long periods) const noexcept {
  return static_cast<double>(periods) * (periods > 0 ? step_up_m : step_down_m);
}

StepDriveParams step_drive_options(const Connection& c, StepDriveParams p, double max_voltage_V,
                                   double max_frequency_Hz) {
  p.voltage_V = connection_number(c, "voltage_V", p.voltage_V, 1e-3, max_voltage_V);
  p.frequency_Hz = connection_number(c, "frequency_Hz", p.frequency_Hz, 1.0, max_frequency_Hz);
  p.max_run_s = connection_number(c, "max_run_s", p.max_run_s, 1e-4, 1.0);
  p.step_up_m = 1e-9 * connection_number(c, "step_up_nm", 1e9 * p.step_up_m, 1e-3, 1e4);
  p.step_down_m = 1e-9 * connection_number(c, "step_down_nm", 1e9 * p.step_down_m, 1e-3, 1e4);
  p.deadband_m = 1e-9 * connection_number(c, "deadband_nm", 1e9 * p.deadband_m, 0.0, 1e5);
  return p;
}

void steps_from_model(StepDriveParams& p, const stickslip::StickSlipParams& axis) {
  if (p.step_up_m != 0.0 && p.step_down_m != 0.0) return;
  const stickslip::ActuatorModel model(axis);
  const double v = std::min(p.voltage_V, axis.drive.max_V);
  if (p.step_up_m == 0.0)
    p.step_up_m =
        std::abs(motion::measure_step(model, v, p.frequency_Hz, stickslip::Direction::kForward, 3, 6).step_m);
  if (p.step_down_m == 0.0)
    p.step_down_m = std::abs(
        motion::measure_step(model, v, p.frequency_Hz, stickslip::Direction::kBackward, 3, 6).step_m);
}

}  // namespace mc::drivers

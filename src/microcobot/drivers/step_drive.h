#pragma once
/// @file
/// An open-loop stepped axis whose loop a driver closes itself at the step level, for a controller
/// that knows nothing of where the slider is (anc300: every axis; smaract-mcs2: a channel without
/// sensor, option sensorless=step). Its position is counted: the sum of the periods sent times s,
/// the step of one period at the set amplitude and frequency (up or down), from 0 at the first
/// configure. s comes from the platform's stick-slip model (the model identified for these axes)
/// unless given; the true step's error is unknown to the count, which drifts by it.
///
///   error e = target - counted position; n = max(1, round(|e| / s)) periods toward it, none while
///   |e| is within the dead band (half a step unless given), at most frequency * max_run_s per run
///   so that a moving target is followed.

#include <string_view>

#include "microcobot/drivers/line_client.h"
#include "microcobot/stickslip/stickslip_params.h"

namespace mc::drivers {

struct StepDriveParams {
  double voltage_V = 60.0;                    ///< the sawtooth amplitude
  double frequency_Hz = 1000.0;               ///< periods per second
  double max_run_s = 0.02;                    ///< the longest run of one command
  double step_up_m = 0.0, step_down_m = 0.0;  ///< s per period; 0: from the model
  /// No step while |e| is below it; 0: half a step (the count's own resolution). A controller whose
  /// runs start with a slip of their own (the twins: docs/hardware.md) needs it wider than that slip.
  double deadband_m = 0.0;

  /// `controller` names the range in the messages: amplitude (0, max_voltage_V], frequency [1,
  /// max_frequency_Hz]. The steps must be known (given, or steps_from_model).
  void validate(std::string_view controller, double max_voltage_V, double max_frequency_Hz) const;
  /// The periods of the next run toward an error `error_m` (signed: + up), 0 within the dead band.
  long long periods_toward(double error_m) const noexcept;
  /// What `periods` (signed) move the counted position by.
  double displacement_m(long long periods) const noexcept;
  /// The most periods one run plays.
  long long max_periods() const noexcept;
};

/// The options that set a StepDriveParams, for check_connection_options.
inline constexpr std::string_view kStepDriveOptions =
    "voltage_V, frequency_Hz, max_run_s, step_up_nm, step_down_nm, deadband_nm";

/// `defaults` with the options of `c` over it (voltage_V within (0, max_voltage_V], frequency_Hz
/// within [1, max_frequency_Hz]); a value out of range is refused naming the option.
StepDriveParams step_drive_options(const Connection& c, StepDriveParams defaults, double max_voltage_V,
                                   double max_frequency_Hz);

/// Fills a step left at 0 from the model `axis`: the step of one period at the amplitude (at most
/// the model's drive range) and frequency, as the platform's StepMap measures its grid (3 periods
/// of warm-up, 6 averaged). A model that does not step leaves it 0 (validate refuses it).
void steps_from_model(StepDriveParams& p, const stickslip::StickSlipParams& axis);

}  // namespace mc::drivers

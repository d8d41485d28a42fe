#pragma once
/// @file
/// A synthetic measurement campaign (the experiments of thesis §2.5.2 run on the simulator, with
/// the sensor effects of §2.5.1): the data the round-trip proof identifies, and the demo data of
/// `microcobot identify synth`. Files follow the layout `identify all --in DIR` reads:
///   pe_step.csv  PE without slider, voltage step, ~1 MHz (§2.5.2.1, Fig. 2.10)
///   step.csv     actuator in scanning mode, voltage step, 25 kHz (Fig. 2.11)
///   sine.csv     actuator in scanning mode, sine 0..A at f (§2.5.2.2, Fig. 2.12)
///   sawtooth_<A>V_<f>Hz_<forward|backward>.csv   sawtooth runs (§2.5.2.3)
/// Every file has the columns t_s,u_V,x_m.

#include <filesystem>
#include <functional>
#include <vector>

#include "microcobot/stickslip/ident_breakaway.h"
#include "microcobot/stickslip/ident_record.h"
#include "microcobot/stickslip/stickslip_params.h"

namespace mc::stickslip {

struct CampaignPlan {
  double pe_step_V = 90.0, pe_fs_Hz = 1e6, pe_duration_s = 1e-3;    ///< thesis: 90 V, "1 mHz" = 1 MHz
  double step_V = 20.0, step_fs_Hz = 25e3, step_duration_s = 0.03;  ///< below the slip threshold
  double pe_pre_trigger_s = 1e-4, step_pre_trigger_s = 2e-3;        ///< rest recorded before the steps
  double sine_V = 40.0, sine_Hz = 50.0, sine_fs_Hz = 25e3, sine_periods = 2.0;  ///< thesis: 40 V, 50 Hz
  std::vector<double> amplitudes_V = {40, 60, 80, 100};
  std::vector<double> frequencies_Hz = {100, 500, 1000};
  double sawtooth_fs_Hz = 100e3;
  int sawtooth_periods = 6;       ///< recorded periods per run (>= 3)
  double sawtooth_min_s = 0.006;  ///< at least this long (more periods at high frequency)
};

/// The sawtooth record of one run (one settling period is part of the record).
MeasuredRecord measure_sawtooth(const ActuatorModel& model, double amplitude_V, double frequency_Hz,
                                Direction direction, const CampaignPlan& plan, const SensorEffects& sensor);

/// Simulates the whole campaign on `truth` and writes it to `dir` (atomic files). Sawtooth runs are
/// simulated on all cores; `progress(done, total)` is called per run. Returns the file count.
std::size_t write_campaign(const std::filesystem::path& dir, const StickSlipParams& truth,
                           const CampaignPlan& plan, const SensorEffects& sensor,
                           const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace mc::stickslip

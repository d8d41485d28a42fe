#pragma once
/// @file
/// Iterative learning on a repeated reference (motion/iterative_learning.h): a 1-D case of the
/// tuning or validation set (validation_set.h) run trial after trial on the simulated axis, each
/// trial from the same start (power-up, or the lead-in move and its rest) as a cell's repeated
/// transport would, its sensor noise a new stream every trial, the correction learned after each.
/// The metrics are those of run_case(): RMS and max of the true x - r while the move runs.

#include <cstdint>
#include <vector>

#include "microcobot/motion/iterative_learning.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/stickslip/actuator.h"
#include "microcobot/studies/tracking_run.h"
#include "microcobot/studies/validation_set.h"

namespace mc::studies {

struct LearningTrial {
  int trial = 0;                  ///< 0: the first run (with whatever correction was there)
  double rms_m = 0.0;             ///< RMS of x - r (true position) while the move runs
  double max_m = 0.0;             ///< max |x - r| while the move runs
  double final_m = 0.0;           ///< |x - r| at the end
  double correction_max_m = 0.0;  ///< max |u| the trial ran with
  /// RMS of the measured error's change from the previous trial, tick by tick over the
  /// reference (0 for the first trial of the call): what did not repeat, which no learning
  /// indexed by time can correct.
  double change_rms_m = 0.0;
};

/// The identity of a 1-D case's reference (its samples at the 10 kHz tick, its start) mixed with
/// `axis_id`: IterativeLearning::begin_trial() forgets a correction learned on another one.
std::uint64_t case_identity(const ValidationCase& c, std::uint64_t axis_id = 0);

/// Control ticks of a 1-D case's reference clock (lead-in, move and tail).
long case_ticks(const ValidationCase& c);

/// `trials` trials of the 1-D case `c` with the tracking controller of `setup`, learning into
/// `ilc` after each (`learn` false: the correction is used, not changed). Trial t's sensor noise
/// stream is c.sensor_seed + 1000 (first_trial + t). Throws mc::InvalidParams for a 3-D case or a
/// reference longer than the learner's buffers.
std::vector<LearningTrial> run_learning(const stickslip::ActuatorModel& model, const motion::StepMap& map,
                                        const TrackerSetup& setup, const ValidationCase& c,
                                        motion::IterativeLearning& ilc, int trials, int first_trial = 0,
                                        bool learn = true, std::uint64_t axis_id = 0);

}  // namespace mc::studies

#pragma once
/// @file
/// The whole identification of one stick-slip axis (thesis §2.5.2, steps 1-3 in order) from a
/// directory of measurements (layout in ident_synthetic.h / docs/model.md):
///  1. pe_step.csv (optional: PE without slider) -> PE modes, gain split;
///     step.csv -> the two asperities (rho0, rho1 each) and the slider mass split;
///  2. sine.csv -> PI thresholds and weights (NNLS) and the PE's static gain g;
///  3. sawtooth_*.csv -> z_ba of every run and the table z_ba(amplitude, frequency, direction).
/// The result is one StickSlipParams: `base` with every identified field replaced.

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "microcobot/stickslip/ident_breakaway.h"
#include "microcobot/stickslip/ident_friction_modes.h"
#include "microcobot/stickslip/ident_hysteresis.h"
#include "microcobot/stickslip/ident_pe_modes.h"

namespace mc::stickslip {

struct IdentifyAllOptions {
  int operators = 35;  ///< PI operators (thesis §2.5.2.2: n = 35)
  BreakawayOptions breakaway;
};

struct IdentifyAllResult {
  std::optional<PeModesResult> pe;  ///< absent when the directory has no pe_step.csv
  FrictionModesResult friction;
  HysteresisResult hysteresis;
  BreakawayResult breakaway;
  StickSlipParams params;          ///< the identified axis
  std::vector<std::string> notes;  ///< what was kept from `base`, skipped runs, filled cells
};

/// Runs the three steps on the files of `dir`. `progress(task, done, total)` reports the steps and
/// the sawtooth runs. Throws mc::InvalidInput for a missing or malformed file and
/// mc::ComputationFailed when a step fails.
IdentifyAllResult identify_all(
    const std::filesystem::path& dir, const StickSlipParams& base, const IdentifyAllOptions& options = {},
    const std::function<void(const std::string&, std::size_t, std::size_t)>& progress = {});

/// Combines identified parts into parameters: PE modes (if any) and gain split, asperities, PI
/// weights with the static gain g from the hysteresis step (the PE step's g assumes H(U) = U).
StickSlipParams combine_identified(const StickSlipParams& base, const PeModesResult* pe,
                                   const FrictionModesResult& friction, const HysteresisResult& hysteresis);

}  // namespace mc::stickslip

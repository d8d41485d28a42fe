#pragma once
/// @file
/// The whole identification of one stick-slip axis (thesis §2.5.2, steps 1-3 in order) from a
/// directory of measurements (layout in ident_synthetic.h / docs/concepts/stick-slip.md):
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
  std::optional<PeModesResult> pe;  ///< absent without a pe_step record (pe_step.csv)
  FrictionModesResult friction;
  HysteresisResult hysteresis;
  BreakawayResult breakaway;
  StickSlipParams params;          ///< the identified axis
  std::vector<std::string> notes;  ///< what was kept from `base`, skipped runs, filled cells
};

/// The measurements the three steps take, whatever they were read from.
struct IdentificationRecords {
  std::optional<MeasuredRecord> pe_step;  ///< PE without slider (optional)
  MeasuredRecord step;                    ///< actuator step response (slider position)
  MeasuredRecord sine;                    ///< scanning-mode sine response
  std::vector<SawtoothRun> sawtooth;      ///< at least one run
};

/// Reads the records of `dir` (pe_step.csv optional, step.csv, sine.csv, sawtooth_*.csv): all
/// of them before any computation, so a malformed file fails first. Throws mc::InvalidInput.
IdentificationRecords read_identification_records(const std::filesystem::path& dir);

using IdentifyProgress = std::function<void(const std::string&, std::size_t, std::size_t)>;

/// Runs the three steps on `records`. `progress(task, done, total)` reports the steps and the
/// sawtooth runs. Throws mc::InvalidInput when there is no sawtooth run and
/// mc::ComputationFailed when a step fails.
IdentifyAllResult identify_all(const IdentificationRecords& records, const StickSlipParams& base,
                               const IdentifyAllOptions& options = {}, const IdentifyProgress& progress = {});
/// The same on the files of `dir` (read_identification_records()).
IdentifyAllResult identify_all(const std::filesystem::path& dir, const StickSlipParams& base,
                               const IdentifyAllOptions& options = {}, const IdentifyProgress& progress = {});

/// Combines identified parts into parameters: PE modes (if any) and gain split, asperities, PI
/// weights with the static gain g from the hysteresis step (the PE step's g assumes H(U) = U).
StickSlipParams combine_identified(const StickSlipParams& base, const PeModesResult* pe,
                                   const FrictionModesResult& friction, const HysteresisResult& hysteresis);

}  // namespace mc::stickslip

#pragma once
/// @file
/// Measured records of one stick-slip axis for identification (thesis §2.5.1): a CSV with the
/// columns `t_s,u_V,x_m` (time, drive voltage, interferometer position), uniformly sampled.
/// Also the synthetic "measurement" of a simulated axis with the sensor effects of §2.5.1
/// (interferometer quantisation and noise, voltage noise), used by the round-trip proofs.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "microcobot/core/csv.h"
#include "microcobot/stickslip/actuator.h"
#include "microcobot/stickslip/drive.h"

namespace mc::stickslip {

/// One uniformly sampled record. `source` names it in error messages.
struct MeasuredRecord {
  std::string source;
  std::vector<double> t_s, u_V, x_m;

  std::size_t size() const { return t_s.size(); }
  /// Sample period [s] (mean spacing; uniformity is checked when the record is built).
  double dt_s() const;
  double fs_Hz() const { return 1.0 / dt_s(); }
  double duration_s() const { return t_s.back() - t_s.front(); }
};

/// Builds a record from a table with the columns t_s, u_V, x_m. Throws mc::InvalidInput
/// "<source>: ..." for a missing column, fewer than 16 samples, non-increasing time or a
/// sampling that is not uniform (spacing deviating by more than 1% from the mean).
MeasuredRecord record_from_table(const CsvTable& table, const std::string& source);
/// read_csv() + record_from_table(); a .mat file (is_mat_file) holds the variables t, u, x instead.
MeasuredRecord read_record(const std::filesystem::path& file);
/// Writes the record as `t_s,u_V,x_m` (atomic); `comment` lines go above the header.
void write_record(const std::filesystem::path& file, const MeasuredRecord& rec,
                  const std::vector<std::string>& comment = {});

/// Throws mc::InvalidInput "<source>: record too short for <what> (need ..., got ...)" unless
/// the record holds at least `min_samples` samples and lasts at least `min_duration_s`.
void require_record_length(const MeasuredRecord& rec, std::size_t min_samples, double min_duration_s,
                           const std::string& what);

/// Sensor effects of the thesis's set-up (§2.5.1): interferometer resolution 0.1 nm, a white
/// position noise, and a white noise on the recorded voltage relative to the drive amplitude.
struct SensorEffects {
  double quantisation_m = 0.1e-9;        ///< interferometer resolution (§2.5.1: 0.1 nm)
  double position_noise_rms_m = 1e-9;    ///< white position noise, RMS
  double voltage_noise_fraction = 0.01;  ///< RMS voltage noise / drive amplitude
  std::uint64_t seed = 1;
  /// When >= 0: the RMS voltage noise in volts, whatever the amplitude (replaces the fraction;
  /// `identify synth --voltage-noise`).
  double voltage_noise_rms_V = -1.0;
};

/// What the interferometer looks at.
enum class Measured { kSlider, kPiezo };

/// Simulates `wave` on `model` for `duration_s` and samples it at `fs_Hz` (which must be an
/// integer divisor of 1 / model.dt_s()), then applies `sensor`. `measured` selects x2 (slider)
/// or x1 (PE without slider, thesis §2.5.2.1). The waveform starts after `pre_trigger_s` at rest
/// (a recorder's pre-trigger); the record lasts pre_trigger_s + duration_s. Throws
/// mc::InvalidParams for a bad rate and mc::ComputationFailed if the simulation diverges.
MeasuredRecord measure(const ActuatorModel& model, const Waveform& wave, double duration_s, double fs_Hz,
                       const SensorEffects& sensor, Measured measured = Measured::kSlider,
                       double pre_trigger_s = 0.0);

/// Mean slider velocity over whole drive periods [m/s]: the difference of the position averaged
/// over the last and over the first full period after `skip_periods`, divided by their time
/// distance (insensitive to the sawtooth's intra-period motion and to white noise).
/// Throws mc::InvalidInput if fewer than skip_periods + 2 full periods are recorded.
double mean_velocity(const std::vector<double>& t_s, const std::vector<double>& x_m, double frequency_Hz,
                     int skip_periods = 1, const std::string& source = "record");

}  // namespace mc::stickslip

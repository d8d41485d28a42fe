#include "microcobot/stickslip/ident_record.h"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/mat_file.h"
#include "microcobot/core/rng.h"

namespace mc::stickslip {

double MeasuredRecord::dt_s() const {
  if (t_s.size() < 2) return 0.0;
  return (t_s.back() - t_s.front()) / static_cast<double>(t_s.size() - 1);
}

MeasuredRecord record_from_table(const CsvTable& table, const std::string& source) {
  MeasuredRecord r;
  r.source = source;
  r.t_s = table.column("t_s");
  r.u_V = table.column("u_V");
  r.x_m = table.column("x_m");
  const std::size_t n = r.t_s.size();
  if (n < 16) throw InvalidInput(source, 0, fmt::format("record too short: {} samples (need >= 16)", n));
  for (std::size_t i = 1; i < n; ++i) {
    if (!(r.t_s[i] > r.t_s[i - 1])) {
      // Data rows start on line 2 (after the header); comments would shift this only upwards.
      throw InvalidInput(
          source, i + 2,
          fmt::format("time t_s must be strictly increasing ({} after {})", r.t_s[i], r.t_s[i - 1]));
    }
  }
  const double dt = r.dt_s();
  for (std::size_t i = 1; i < n; ++i) {
    const double d = r.t_s[i] - r.t_s[i - 1];
    if (std::abs(d - dt) > 0.01 * dt) {
      throw InvalidInput(source, i + 2,
                         fmt::format("sampling must be uniform (step {:.6g} s vs mean {:.6g} s)", d, dt));
    }
  }
  return r;
}

MeasuredRecord read_record(const std::filesystem::path& file) {
  // A .mat file holds the same record as the variables t, u, x (SI units, docs/cli.md).
  const CsvTable t =
      is_mat_file(file) ? read_mat_columns(file, {"t", "u", "x"}, {"t_s", "u_V", "x_m"}) : read_csv(file);
  return record_from_table(t, file.string());
}

void write_record(const std::filesystem::path& file, const MeasuredRecord& rec,
                  const std::vector<std::string>& comment) {
  CsvTable t;
  t.add_column("t_s", rec.t_s);
  t.add_column("u_V", rec.u_V);
  t.add_column("x_m", rec.x_m);
  write_csv(file, t, comment);
}

void require_record_length(const MeasuredRecord& rec, std::size_t min_samples, double min_duration_s,
                           const std::string& what) {
  if (rec.size() < min_samples || rec.duration_s() < min_duration_s * (1.0 - 1e-9)) {
    throw InvalidInput(
        rec.source, 0,
        fmt::format("record too short for {} (need >= {} samples and >= {:.4g} s, got {} samples, "
                    "{:.4g} s)",
                    what, min_samples, min_duration_s, rec.size(), rec.duration_s()));
  }
}

MeasuredRecord measure(const ActuatorModel& model, const Waveform& wave, double duration_s, double fs_Hz,
                       const SensorEffects& sensor, Measured measured, double pre_trigger_s) {
  require_positive(fs_Hz, "fs_Hz");
  require_positive(duration_s, "duration_s");
  require_non_negative(pre_trigger_s, "pre_trigger_s");
  wave.validate(model.params().drive);
  const double dt = model.dt_s();
  const double ratio = 1.0 / (fs_Hz * dt);
  const long every = std::lround(ratio);
  require(every >= 1 && std::abs(ratio - static_cast<double>(every)) < 1e-6 * ratio, "fs_Hz",
          "must divide the simulation rate 1/dt_s", fs_Hz);
  ActuatorState st = model.initial_state();
  model.set_operating_point(st, wave.amplitude_V, wave.frequency_Hz, wave.direction);
  const auto steps = static_cast<long>(std::llround((duration_s + pre_trigger_s) / dt));
  Rng rng(sensor.seed);
  MeasuredRecord r;
  r.source = "simulated " + to_string(wave.kind);
  const auto n = static_cast<std::size_t>(steps / every + 1);
  r.t_s.reserve(n);
  r.u_V.reserve(n);
  r.x_m.reserve(n);
  const double u_sigma = sensor.voltage_noise_rms_V >= 0.0 ? sensor.voltage_noise_rms_V
                                                           : sensor.voltage_noise_fraction * wave.amplitude_V;
  auto record = [&] {
    r.t_s.push_back(st.t_s);
    r.u_V.push_back(st.u_V + u_sigma * rng.normal());
    double xi = (measured == Measured::kSlider ? model.slider_position(st) : st.x1_m()) +
                sensor.position_noise_rms_m * rng.normal();
    if (sensor.quantisation_m > 0.0) xi = sensor.quantisation_m * std::round(xi / sensor.quantisation_m);
    r.x_m.push_back(xi);
  };
  record();
  for (long k = 1; k <= steps; ++k) {
    model.step(st, wave.segment(static_cast<double>(k - 1) * dt - pre_trigger_s, dt));
    if (st.diverged) {
      throw ComputationFailed(fmt::format("simulated measurement diverged at t = {:.6g} s", st.t_s));
    }
    if (k % every == 0) record();
  }
  // The state's time accumulates sub-steps: use the exact sample times.
  for (std::size_t i = 0; i < r.t_s.size(); ++i) r.t_s[i] = static_cast<double>(i) / fs_Hz;
  return r;
}

double mean_velocity(const std::vector<double>& t_s, const std::vector<double>& x_m, double frequency_Hz,
                     int skip_periods, const std::string& source) {
  const std::size_t n = t_s.size();
  if (n < 4 || x_m.size() != n) throw InvalidInput(source, 0, "record too short for a mean velocity");
  const double period = 1.0 / frequency_Hz;
  const double t0 = t_s.front() + skip_periods * period;
  const auto periods = static_cast<long>(std::floor((t_s.back() - t0) / period + 1e-9));
  if (periods < 2) {
    throw InvalidInput(
        source, 0,
        fmt::format("record too short for a mean velocity at {:g} Hz (need >= {} full periods, got "
                    "{:.2f})",
                    frequency_Hz, skip_periods + 2, (t_s.back() - t_s.front()) / period));
  }
  auto window_mean = [&](double a, double b, double& tm) {
    double sx = 0.0, st = 0.0;
    std::size_t k = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (t_s[i] >= a && t_s[i] < b) {
        sx += x_m[i];
        st += t_s[i];
        ++k;
      }
    }
    if (k == 0) throw InvalidInput(source, 0, "sampling too coarse for one drive period");
    tm = st / static_cast<double>(k);
    return sx / static_cast<double>(k);
  };
  double ta = 0.0, tb = 0.0;
  const double xa = window_mean(t0, t0 + period, ta);
  const double tl = t0 + static_cast<double>(periods - 1) * period;
  const double xb = window_mean(tl, tl + period, tb);
  return (xb - xa) / (static_cast<double>(periods - 1) * period);
}

}  // namespace mc::stickslip

#include "microcobot/stickslip/ident_breakaway.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <string_view>
#include <thread>

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc::stickslip {

double simulated_mean_velocity(const ActuatorModel& model, const Waveform& wave, double z_ba_m, int periods) {
  const double dt = model.dt_s();
  const double period = 1.0 / wave.frequency_Hz;
  const double t_first = period;                                // after one settling period
  const double t_last = period * static_cast<double>(periods);  // start of the last window
  const double t_end = t_last + period;
  ActuatorState s = model.initial_state();
  s.z_ba_m = z_ba_m;
  const auto steps = static_cast<long>(std::ceil(t_end / dt));
  double sum_a = 0.0, sum_b = 0.0, ta = 0.0, tb = 0.0;
  long na = 0, nb = 0;
  for (long k = 1; k <= steps; ++k) {
    const double t = static_cast<double>(k) * dt;
    model.step(s, wave.segment(t - dt, dt));
    if (s.diverged) throw ComputationFailed(fmt::format("simulation diverged at t = {:.6g} s", t));
    if (t >= t_first && t < t_first + period) {
      sum_a += model.slider_position(s);
      ta += t;
      ++na;
    } else if (t >= t_last && t < t_end) {
      sum_b += model.slider_position(s);
      tb += t;
      ++nb;
    }
  }
  if (na == 0 || nb == 0) throw ComputationFailed("drive period shorter than the simulation step");
  const double xa = sum_a / static_cast<double>(na), xb = sum_b / static_cast<double>(nb);
  return (xb - xa) / (tb / static_cast<double>(nb) - ta / static_cast<double>(na));
}

namespace {

RunFit fit_run(const SawtoothRun& run, const ActuatorModel& model, const BreakawayOptions& o) {
  RunFit r;
  r.name = run.name;
  r.amplitude_V = run.amplitude_V;
  r.frequency_Hz = run.frequency_Hz;
  r.direction = run.direction;
  const auto& p = model.params();
  try {
    const Waveform wave =
        make_waveform(WaveKind::kSawtooth, run.amplitude_V, run.frequency_Hz, run.direction, p.drive);
    r.v_measured_m_s = mean_velocity(run.rec.t_s, run.rec.x_m, run.frequency_Hz, 1, run.rec.source);
    const double stroke = p.pe.static_gain_m_V * pi_loading_curve(p.hysteresis, run.amplitude_V);
    const double per_period = std::abs(r.v_measured_m_s) / run.frequency_Hz;
    if (per_period < std::max(1e-9, o.no_step_fraction * stroke)) {
      r.skipped = fmt::format("never steps (net motion {:.3g} nm per period)", per_period * 1e9);
      return r;
    }
    const double sign = run.direction == Direction::kForward ? 1.0 : -1.0;
    if (r.v_measured_m_s * sign < 0.0) {
      r.skipped = "moves against its drive direction";
      return r;
    }
    const int periods =
        std::max(o.sim_periods + 1, static_cast<int>(std::ceil(o.min_sim_s * run.frequency_Hz)));
    const double target = std::abs(r.v_measured_m_s);
    auto speed = [&](double log_z) {
      ++r.simulations;
      return sign * simulated_mean_velocity(model, wave, std::exp(log_z), periods);
    };
    // Coarse scan from the stroke down: the largest z_ba whose speed reaches the target.
    const double hi = std::log(1.2 * stroke), lo = std::log(0.02 * stroke);
    double z_hi = hi, v_hi = speed(hi), z_lo = 0.0, v_lo = 0.0;
    bool bracket = false;
    double v_max = v_hi;
    for (int i = 1; i < o.scan_points; ++i) {
      const double z = hi + (lo - hi) * static_cast<double>(i) / static_cast<double>(o.scan_points - 1);
      const double v = speed(z);
      v_max = std::max(v_max, v);
      if (v >= target) {
        z_lo = z;
        v_lo = v;
        bracket = true;
        break;
      }
      z_hi = z;
      v_hi = v;
    }
    if (!bracket) {
      r.skipped =
          fmt::format("the model cannot reach the measured speed {:.4g} m/s (max {:.4g} m/s)", target, v_max);
      return r;
    }
    // Illinois regula falsi on f(z) = v(z) - target, f(z_lo) >= 0 > f(z_hi), in log z.
    double f_lo = v_lo - target, f_hi = v_hi - target;
    int side = 0;
    double z = z_lo;
    for (int it = 0; it < o.max_iterations && (z_hi - z_lo) > o.rel_tol; ++it) {
      z = (z_lo * f_hi - z_hi * f_lo) / (f_hi - f_lo);
      if (!(z > z_lo && z < z_hi)) z = 0.5 * (z_lo + z_hi);
      const double f = speed(z) - target;
      if (f >= 0.0) {
        z_lo = z;
        f_lo = f;
        if (side == -1) f_hi *= 0.5;
        side = -1;
      } else {
        z_hi = z;
        f_hi = f;
        if (side == 1) f_lo *= 0.5;
        side = 1;
      }
    }
    // The crossing: interpolate within the final bracket.
    z = (f_hi - f_lo) != 0.0 ? (z_lo * f_hi - z_hi * f_lo) / (f_hi - f_lo) : 0.5 * (z_lo + z_hi);
    z = std::clamp(z, z_lo, z_hi);
    r.z_ba_m = std::exp(z);
    r.v_simulated_m_s = sign * (speed(z));
    r.ok = true;
  } catch (const Error& e) {
    r.skipped = e.what();
  }
  return r;
}

/// The value at `a` of the least-squares line through the (amplitude, z_ba) points of the fitted
/// cells of column j (one cell: its value). All of them, not the nearest few: a run just above the
/// threshold steps erratically and its z_ba is the least certain, so a line through the nearest
/// ones alone tilted with it (2 kHz column of `identify synth --grid full`: 10 V at -61 %).
double column_line(const std::vector<std::vector<double>>& g, const std::vector<std::vector<bool>>& have,
                   const std::vector<double>& amps, std::size_t j, double a) {
  std::vector<std::size_t> rows;
  for (std::size_t i = 0; i < amps.size(); ++i)
    if (have[i][j]) rows.push_back(i);
  if (rows.size() == 1) return g[rows[0]][j];
  double ma = 0.0, mz = 0.0;
  for (std::size_t i : rows) ma += amps[i] / static_cast<double>(rows.size());
  for (std::size_t i : rows) mz += g[i][j] / static_cast<double>(rows.size());
  double saa = 0.0, saz = 0.0;
  for (std::size_t i : rows) {
    saa += (amps[i] - ma) * (amps[i] - ma);
    saz += (amps[i] - ma) * (g[i][j] - mz);
  }
  return mz + (saa > 0.0 ? saz / saa : 0.0) * (a - ma);
}

/// Fills missing cells of one direction's grid. Between two fitted cells of a frequency column:
/// linear along amplitude (`filled`). Beyond the column's fitted cells (runs below the stepping
/// threshold never step, so they carry no z_ba): extrapolated along the line of the column's
/// fitted cells (z_ba is close to affine in amplitude, thesis Fig. 2.13), not copied from the
/// nearest one, which put z_ba of the near-threshold cells too high by the slope times the gap
/// (`extrapolated`, floored at half the direction's smallest fitted z_ba). A column without any
/// fitted cell takes the nearest frequency's values (`extrapolated`).
void fill_grid(std::vector<std::vector<double>>& g, const std::vector<std::vector<bool>>& have,
               const std::vector<double>& amps, const std::string& dir, std::vector<std::string>& filled,
               std::vector<std::string>& extrapolated, const std::vector<double>& freqs) {
  const std::size_t na = amps.size(), nf = freqs.size();
  double z_min = HUGE_VAL;
  for (std::size_t i = 0; i < na; ++i)
    for (std::size_t j = 0; j < nf; ++j)
      if (have[i][j]) z_min = std::min(z_min, g[i][j]);
  for (std::size_t j = 0; j < nf; ++j) {
    for (std::size_t i = 0; i < na; ++i) {
      if (have[i][j]) continue;
      long lo = -1, hi = -1;
      for (long k = static_cast<long>(i) - 1; k >= 0; --k) {
        if (have[static_cast<std::size_t>(k)][j]) {
          lo = k;
          break;
        }
      }
      for (std::size_t k = i + 1; k < na; ++k) {
        if (have[k][j]) {
          hi = static_cast<long>(k);
          break;
        }
      }
      const std::string cell = fmt::format("{} {:g} V {:g} Hz", dir, amps[i], freqs[j]);
      if (lo >= 0 && hi >= 0) {
        const auto l = static_cast<std::size_t>(lo), h = static_cast<std::size_t>(hi);
        const double t = (amps[i] - amps[l]) / (amps[h] - amps[l]);
        g[i][j] = g[l][j] * (1.0 - t) + g[h][j] * t;
        filled.push_back(cell);
      } else if (lo >= 0 || hi >= 0) {
        g[i][j] = std::max(column_line(g, have, amps, j, amps[i]), 0.5 * z_min);
        extrapolated.push_back(cell);
      }  // else: the whole column is missing, second pass along frequency
    }
  }
  for (std::size_t i = 0; i < na; ++i) {
    for (std::size_t j = 0; j < nf; ++j) {
      if (g[i][j] > 0.0) continue;
      double best = -1.0, dist = HUGE_VAL;
      for (std::size_t k = 0; k < nf; ++k) {
        if (g[i][k] > 0.0 && std::abs(std::log(freqs[k] / freqs[j])) < dist) {
          dist = std::abs(std::log(freqs[k] / freqs[j]));
          best = g[i][k];
        }
      }
      if (best > 0.0) {
        g[i][j] = best;
        extrapolated.push_back(fmt::format("{} {:g} V {:g} Hz", dir, amps[i], freqs[j]));
      }
    }
  }
}

}  // namespace

BreakawayResult identify_breakaway(const std::vector<SawtoothRun>& runs, const ActuatorModel& model,
                                   const BreakawayOptions& options,
                                   const std::function<void(std::size_t, std::size_t)>& progress) {
  if (runs.empty()) throw InvalidInput("no sawtooth run to identify the break-away strain from");
  BreakawayResult out;
  out.runs.resize(runs.size());
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> done{0};
  std::mutex mutex;
  auto worker = [&] {
    for (std::size_t i = next++; i < runs.size(); i = next++) {
      out.runs[i] = fit_run(runs[i], model, options);
      const std::size_t d = ++done;
      if (progress) {
        const std::lock_guard<std::mutex> lock(mutex);
        progress(d, runs.size());
      }
    }
  };
  unsigned threads = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  threads = std::min<unsigned>(threads, static_cast<unsigned>(runs.size()));
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();

  // The grid of the runs.
  std::vector<double> amps, freqs;
  for (const auto& r : runs) {
    amps.push_back(r.amplitude_V);
    freqs.push_back(r.frequency_Hz);
  }
  auto uniq = [](std::vector<double>& v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end(),
                        [](double a, double b) { return std::abs(a - b) <= 1e-9 * std::abs(b); }),
            v.end());
  };
  uniq(amps);
  uniq(freqs);
  auto index = [](const std::vector<double>& axis, double v) {
    std::size_t best = 0;
    for (std::size_t k = 1; k < axis.size(); ++k) {
      if (std::abs(axis[k] - v) < std::abs(axis[best] - v)) best = k;
    }
    return best;
  };
  BreakawayTable& tb = out.table;
  tb.amplitudes_V = amps;
  tb.frequencies_Hz = freqs;
  for (Direction d : {Direction::kForward, Direction::kBackward}) {
    std::vector<std::vector<double>> g(amps.size(), std::vector<double>(freqs.size(), 0.0));
    std::vector<std::vector<bool>> have(amps.size(), std::vector<bool>(freqs.size(), false));
    std::size_t count = 0;
    for (const auto& r : out.runs) {
      if (r.direction != d || !r.ok) continue;
      const std::size_t i = index(amps, r.amplitude_V), j = index(freqs, r.frequency_Hz);
      // Repeated runs at one grid point: mean.
      g[i][j] = have[i][j] ? 0.5 * (g[i][j] + r.z_ba_m) : r.z_ba_m;
      have[i][j] = true;
      ++count;
    }
    if (count == 0) {
      throw ComputationFailed(fmt::format("no usable {} sawtooth run: cannot identify z_ba({})", to_string(d),
                                          d == Direction::kForward ? "+" : "-"));
    }
    fill_grid(g, have, amps, to_string(d), out.filled, out.extrapolated, freqs);
    (d == Direction::kForward ? tb.forward_m : tb.backward_m) = g;
  }
  for (const auto& r : out.runs) out.skipped += r.ok ? 0 : 1;
  tb.validate();
  return out;
}

std::string sawtooth_file_name(double amplitude_V, double frequency_Hz, Direction direction) {
  return fmt::format("sawtooth_{:g}V_{:g}Hz_{}.csv", amplitude_V, frequency_Hz, to_string(direction));
}

namespace {

/// Consumes `prefix` from the front of `s`; false when `s` does not start with it.
bool consume(std::string_view& s, std::string_view prefix) {
  if (s.substr(0, prefix.size()) != prefix) return false;
  s.remove_prefix(prefix.size());
  return true;
}

/// Consumes a plain decimal number `[0-9]+(.[0-9]+)?` (no sign, no exponent) into `value`.
bool consume_decimal(std::string_view& s, double& value) {
  auto digits = [&s](std::size_t from) {
    std::size_t i = from;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
    return i;
  };
  std::size_t end = digits(0);
  if (end == 0) return false;
  if (end < s.size() && s[end] == '.') {
    const std::size_t frac_end = digits(end + 1);
    if (frac_end == end + 1) return false;
    end = frac_end;
  }
  value = std::stod(std::string(s.substr(0, end)));
  s.remove_prefix(end);
  return true;
}

}  // namespace

bool parse_sawtooth_file_name(const std::string& name, double& amplitude_V, double& frequency_Hz,
                              Direction& direction) {
  // sawtooth_<amplitude>V_<frequency>Hz_<forward|backward>.csv
  std::string_view s = name;
  double a = 0.0, f = 0.0;
  if (!consume(s, "sawtooth_") || !consume_decimal(s, a) || !consume(s, "V_") || !consume_decimal(s, f) ||
      !consume(s, "Hz_")) {
    return false;
  }
  Direction d{};
  if (s == "forward.csv") {
    d = Direction::kForward;
  } else if (s == "backward.csv") {
    d = Direction::kBackward;
  } else {
    return false;
  }
  if (!(a > 0.0 && f > 0.0)) return false;
  amplitude_V = a;
  frequency_Hz = f;
  direction = d;
  return true;
}

std::vector<SawtoothRun> read_sawtooth_runs(const std::filesystem::path& dir) {
  if (!std::filesystem::is_directory(dir)) throw InvalidInput(dir.string(), 0, "not a directory");
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.rfind("sawtooth_", 0) == 0 && e.path().extension() == ".csv") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    throw InvalidInput(
        dir.string(), 0,
        "no sawtooth run (expected files named sawtooth_<amplitude>V_<frequency>Hz_<forward|backward>"
        ".csv, e.g. sawtooth_60V_500Hz_forward.csv)");
  }
  std::vector<SawtoothRun> runs;
  for (const auto& f : files) {
    SawtoothRun r;
    r.name = f.filename().string();
    if (!parse_sawtooth_file_name(r.name, r.amplitude_V, r.frequency_Hz, r.direction)) {
      throw InvalidInput(f.string(), 0,
                         "file name must read sawtooth_<amplitude>V_<frequency>Hz_<forward|backward>.csv");
    }
    r.rec = read_record(f);
    runs.push_back(std::move(r));
  }
  return runs;
}

}  // namespace mc::stickslip

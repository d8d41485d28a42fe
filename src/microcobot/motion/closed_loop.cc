#include "microcobot/motion/closed_loop.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "microcobot/core/error.h"

namespace mc::motion {

using stickslip::ActuatorModel;
using stickslip::ActuatorState;

int steps_per_tick(const ActuatorModel& model, double control_rate_Hz) {
  require_positive(control_rate_Hz, "control_rate_Hz");
  const double r = 1.0 / (control_rate_Hz * model.dt_s());
  const long n = std::lround(r);
  require(n >= 1 && std::abs(r - static_cast<double>(n)) < 1e-6 * r, "control_rate_Hz",
          "the control period must be a whole number of model steps (integrator.dt_s)", control_rate_Hz);
  return static_cast<int>(n);
}

namespace {

ActuatorState start_state(const ActuatorModel& model, double start_m) {
  const double half = 0.5 * model.params().slider.stroke_m;
  require(std::isfinite(start_m) && std::abs(start_m) <= half, "start_m",
          "must lie within the stroke (+-" + std::to_string(half) + " m)", start_m);
  ActuatorState s = model.initial_state();
  s.x2_m = {start_m, start_m};
  return s;
}

/// Runs `ticks` control ticks of controller `c` on `s`; `record(k, x_true, u)` after each tick.
template <class C, class Rec>
void run_ticks(const ActuatorModel& model, ActuatorState& s, PositionSensor& sensor, C& c, int ratio,
               long ticks, Rec&& record, const std::function<bool()>& stop = {}) {
  const double dt = model.dt_s();
  for (long k = 0; k < ticks; ++k) {
    c.update(sensor.measure(model.slider_position(s)));
    const auto& g = c.generator();
    model.set_operating_point(s, g.amplitude_V(), g.frequency_Hz(), g.direction());
    double u = 0.0;
    for (int i = 0; i < ratio; ++i) {
      const stickslip::DriveSegment d = c.next_drive(dt);
      model.step(s, d);
      u = d.end_V;
    }
    if (s.diverged) {
      throw ComputationFailed("closed-loop simulation diverged (NaN/Inf) at t = " + std::to_string(s.t_s) +
                              " s");
    }
    record(k, model.slider_position(s), u);
    if (stop && stop()) break;
  }
}

double mean(const std::vector<double>& v, std::size_t from) {
  double s = 0.0;
  for (std::size_t i = from; i < v.size(); ++i) s += v[i];
  return v.size() > from ? s / static_cast<double>(v.size() - from) : 0.0;
}

}  // namespace

VelocityRun run_velocity(const ActuatorModel& model, const StepMap* map, const VelocityControlParams& p,
                         VelocityMode mode, double reference_m_s, double duration_s,
                         const PositionSensorParams& sp, double start_m) {
  require(std::isfinite(reference_m_s) && reference_m_s != 0.0, "reference_m_s", "must be finite and != 0",
          reference_m_s);
  require_positive(duration_s, "duration_s");
  VelocityController c(p, mode, map, model.params().drive.slew_rate_V_s);
  c.set_reference(reference_m_s);
  PositionSensor sensor(sp);
  ActuatorState s = start_state(model, start_m);
  const int ratio = steps_per_tick(model, p.control_rate_Hz);
  const double tick = static_cast<double>(ratio) * model.dt_s();
  const double period = 1.0 / p.sawtooth_frequency_Hz;
  const long per = std::max(1L, std::lround(period / tick));  // ticks per sample (one period)
  const long ticks = std::lround(duration_s / tick);
  VelocityRun run;
  double x_prev = model.slider_position(s);
  run_ticks(model, s, sensor, c, ratio, ticks, [&](long k, double x, double) {
    if ((k + 1) % per != 0) return;
    run.t_s.push_back(static_cast<double>(k + 1) * tick);
    run.v_true_m_s.push_back((x - x_prev) / (static_cast<double>(per) * tick));
    run.v_est_m_s.push_back(c.velocity_estimate_m_s());
    run.amplitude_V.push_back(c.amplitude_V());
    x_prev = x;
  });
  require(run.t_s.size() >= 10, "duration_s", "must cover at least 10 sawtooth periods", duration_s);
  run.metrics = velocity_metrics(run, reference_m_s);
  return run;
}

VelocityMetrics velocity_metrics(const VelocityRun& run, double reference_m_s) {
  require(std::isfinite(reference_m_s) && reference_m_s != 0.0, "reference_m_s", "must be finite and != 0",
          reference_m_s);
  require(run.t_s.size() >= 10 && run.v_true_m_s.size() == run.t_s.size(), "run",
          "needs >= 10 periods with one velocity each");
  VelocityMetrics m;
  const std::size_t half = run.t_s.size() / 2;
  m.mean_velocity_m_s = mean(run.v_true_m_s, half);
  m.steady_state_error_rel = (m.mean_velocity_m_s - reference_m_s) / reference_m_s;
  double var = 0.0;
  for (std::size_t i = half; i < run.v_true_m_s.size(); ++i) {
    var += (run.v_true_m_s[i] - m.mean_velocity_m_s) * (run.v_true_m_s[i] - m.mean_velocity_m_s);
  }
  m.ripple_m_s = std::sqrt(var / static_cast<double>(run.v_true_m_s.size() - half));
  // Settling: the first 5-period mean inside +-5 % of the reference that stays inside for
  // kSettleHoldPeriods; later excursions are counted, not waited for.
  const std::size_t w = VelocityMetrics::kSettleWindowPeriods;
  const std::size_t hold = VelocityMetrics::kSettleHoldPeriods;
  std::vector<double> dev;  // |5-period mean / reference - 1| ending at sample i + w - 1
  for (std::size_t i = w; i <= run.v_true_m_s.size(); ++i) {
    double acc = 0.0;
    for (std::size_t j = i - w; j < i; ++j) acc += run.v_true_m_s[j];
    dev.push_back(std::abs(acc / static_cast<double>(w) / reference_m_s - 1.0));
  }
  std::size_t inside = 0;
  for (std::size_t i = 0; i < dev.size(); ++i) {
    inside = dev[i] <= 0.05 ? inside + 1 : 0;
    if (inside < hold) continue;
    const std::size_t first = i + 1 - hold;
    m.settled = true;
    m.settling_time_s = run.t_s[first + w - 1];
    for (std::size_t k = first; k < dev.size(); ++k) {
      m.excursions += dev[k] > 0.05 ? 1 : 0;
      m.max_excursion_rel = std::max(m.max_excursion_rel, dev[k]);
    }
    break;
  }
  if (!m.settled) m.settling_time_s = run.t_s.back();
  return m;
}

namespace {
struct Recorder {
  PositionRun& run;
  long every;
  void operator()(long k, double tick, double x, double u, double mode) {
    if (k % every != 0) return;
    run.t_s.push_back(static_cast<double>(k + 1) * tick);
    run.x_m.push_back(x);
    run.u_V.push_back(u);
    run.mode.push_back(mode);
  }
};
}  // namespace

PositionRun run_position(const ActuatorModel& model, const StepMap& map, const PositionControlParams& p,
                         const PositionSensorParams& sp, double start_m, double target_m, double hold_s,
                         double max_time_s, int max_records) {
  require_non_negative(hold_s, "hold_s");
  require(max_records >= 10, "max_records", "must be >= 10", max_records);
  const double half = 0.5 * model.params().slider.stroke_m;
  require(std::isfinite(target_m) && std::abs(target_m) <= half + 1e-3, "target_m",
          "must lie within 1 mm of the stroke", target_m);
  PositionController c(p, model.params(), map);
  PositionSensor sensor(sp);
  ActuatorState s = start_state(model, start_m);
  const int ratio = steps_per_tick(model, p.control_rate_Hz);
  const double tick = static_cast<double>(ratio) * model.dt_s();
  if (max_time_s <= 0.0) {
    const double speed = std::min(
        p.max_velocity_m_s,
        0.5 * map.max_step_m(p.step_frequency_Hz, stickslip::Direction::kForward) * p.step_frequency_Hz);
    max_time_s = std::abs(target_m - start_m) / std::max(speed, 1e-6) + 0.1 + hold_s;
  }
  const long ticks = std::lround(max_time_s / tick);
  PositionRun run;
  Recorder rec{run, std::max(1L, ticks / max_records)};
  c.set_target(target_m);
  const double dir = target_m >= start_m ? 1.0 : -1.0;
  double overshoot = 0.0, t_hold = -1.0, hold_lo = 1e9, hold_hi = -1e9, u_lo = 1e9, u_hi = -1e9;
  bool stepped_in_hold = false;
  long k_now = 0;
  run_ticks(
      model, s, sensor, c, ratio, ticks,
      [&](long k, double x, double u) {
        k_now = k;
        const double t = static_cast<double>(k + 1) * tick;
        overshoot = std::max(overshoot, dir * (x - target_m));
        if (t_hold < 0.0 && c.mode() == AxisMode::kHold) t_hold = t;
        if (t_hold >= 0.0) {
          hold_lo = std::min(hold_lo, x);
          hold_hi = std::max(hold_hi, x);
          u_lo = std::min(u_lo, u);
          u_hi = std::max(u_hi, u);
          if (c.mode() == AxisMode::kStepping) stepped_in_hold = true;
        }
        rec(k, tick, x, u, static_cast<double>(static_cast<int>(c.mode())));
      },
      [&] {
        return (t_hold >= 0.0 && static_cast<double>(k_now + 1) * tick >= t_hold + hold_s) || c.end_stop();
      });
  auto& m = run.metrics;
  const double x_end = model.slider_position(s);
  m.final_error_m = std::abs(x_end - target_m);
  m.overshoot_m = overshoot;
  m.in_position = t_hold >= 0.0;
  m.move_time_s = m.in_position ? t_hold : static_cast<double>(k_now + 1) * tick;
  m.hold_pp_m = m.in_position ? hold_hi - hold_lo : 0.0;
  m.hold_voltage_pp_V = m.in_position ? u_hi - u_lo : 0.0;
  m.stepped_in_hold = stepped_in_hold;
  m.switches = static_cast<long>(c.switches());
  m.end_stop = c.end_stop();
  return run;
}

PositionRun run_baseline_position(const ActuatorModel& model, const BaselinePositionParams& p,
                                  BaselineKind kind, const PositionSensorParams& sp, double start_m,
                                  double target_m, double duration_s, int max_records) {
  require_positive(duration_s, "duration_s");
  BaselinePositionController c(p, kind, model.params().drive.slew_rate_V_s);
  PositionSensor sensor(sp);
  ActuatorState s = start_state(model, start_m);
  const int ratio = steps_per_tick(model, 10000.0);
  const double tick = static_cast<double>(ratio) * model.dt_s();
  const long ticks = std::lround(duration_s / tick);
  PositionRun run;
  Recorder rec{run, std::max(1L, ticks / max_records)};
  c.set_target(target_m, sensor.measure(model.slider_position(s)));
  const double dir = target_m >= start_m ? 1.0 : -1.0;
  double overshoot = 0.0;
  run_ticks(model, s, sensor, c, ratio, ticks, [&](long k, double x, double u) {
    overshoot = std::max(overshoot, dir * (x - target_m));
    rec(k, tick, x, u, c.generator().running() ? 1.0 : 0.0);
  });
  run.metrics.final_error_m = std::abs(model.slider_position(s) - target_m);
  run.metrics.overshoot_m = overshoot;
  run.metrics.move_time_s = duration_s;
  return run;
}

TrackingRun run_tracking(const ActuatorModel& model, const StepMap& map, const PositionControlParams& p,
                         const PositionSensorParams& sp, double start_m,
                         const std::function<ReferenceSample(double, double)>& reference, double duration_s,
                         int max_records) {
  require_positive(duration_s, "duration_s");
  PositionController c(p, model.params(), map);
  PositionSensor sensor(sp);
  ActuatorState s = start_state(model, start_m);
  const int ratio = steps_per_tick(model, p.control_rate_Hz);
  const double tick = static_cast<double>(ratio) * model.dt_s();
  const long ticks = std::lround(duration_s / tick);
  const long every = std::max(1L, ticks / max_records);
  TrackingRun run;
  double sq = 0.0, mx = 0.0;
  long n = 0;
  double ref_now = start_m;
  // The controller reads the reference of the tick it acts in.
  struct Wrapped {
    PositionController& c;
    const std::function<ReferenceSample(double, double)>& ref;
    double tick;
    double& ref_now;
    long k = 0;
    void update(double x) noexcept {
      const ReferenceSample r = ref(static_cast<double>(k) * tick, tick);
      ref_now = r.x_m;
      c.set_target(r.x_m, r.v_m_s);
      c.update(x);
      ++k;
    }
    stickslip::DriveSegment next_drive(double dt) noexcept { return c.next_drive(dt); }
    const SawtoothGenerator& generator() const noexcept { return c.generator(); }
  } w{c, reference, tick, ref_now};
  run_ticks(model, s, sensor, w, ratio, ticks, [&](long k, double x, double u) {
    const double e = x - ref_now;
    sq += e * e;
    mx = std::max(mx, std::abs(e));
    ++n;
    if (k % every == 0) {
      run.t_s.push_back(static_cast<double>(k + 1) * tick);
      run.ref_m.push_back(ref_now);
      run.x_m.push_back(x);
      run.u_V.push_back(u);
    }
  });
  run.rms_error_m = std::sqrt(sq / static_cast<double>(std::max(1L, n)));
  run.max_error_m = mx;
  return run;
}

}  // namespace mc::motion

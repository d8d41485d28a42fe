#include "microcobot/studies/edge_dip.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc::studies {
namespace {

void check(const EdgeCase& e) {
  const auto bad = [](const char* field, double v, const char* want) {
    throw InvalidInput(fmt::format("edge.{} = {:g}: {}", field, v, want));
  };
  if (!(e.top_V > 0.0 && e.top_V <= 100.0)) bad("top_V", e.top_V, "must lie in (0, 100] V");
  if (!(e.drop_V > 0.0 && e.drop_V <= e.top_V)) bad("drop_V", e.drop_V, "must lie in (0, top_V] V");
  if (!(e.slew_V_s > 0.0 && std::isfinite(e.slew_V_s))) bad("slew_V_s", e.slew_V_s, "must be > 0 V/s");
  if (!(e.ramp_m_s > 0.0 && std::isfinite(e.ramp_m_s))) bad("ramp_m_s", e.ramp_m_s, "must be > 0 m/s");
  if (!(e.unload_V >= 0.0 && e.unload_V <= e.drop_V))
    bad("unload_V", e.unload_V, "must lie in [0, drop_V] V");
  const double half_s = 0.5 * (e.drop_V + e.unload_V) / e.slew_V_s;
  if (!(e.split_delay_s == 0.0 || (e.split_delay_s >= half_s && e.split_delay_s <= 0.1)))
    bad("split_delay_s", e.split_delay_s, "must be 0 or lie in [(ΔV + unload_V) / 2S, 0.1] s");
  const double busy_s = e.split_delay_s + (e.drop_V + e.unload_V) / e.slew_V_s;
  if (!(e.window_s >= 1e-3 + busy_s && e.window_s <= 1.0))
    bad("window_s", e.window_s, "must outlast the edge by 1 ms and be at most 1 s");
}

/// The drive, piecewise linear through its knots (t, u), held after the last: up at `r` V/s to
/// the top, down by ΔV at S (or by two halves, the second `split_delay_s` after the first), up
/// by the unloading at S.
struct EdgeDrive {
  static constexpr std::size_t kMaxKnots = 8;
  std::array<double, kMaxKnots> t{}, u{};
  std::size_t n = 0;

  EdgeDrive(const EdgeCase& e, double ramp_V_s) {
    add(0.0, 0.0);
    add(e.top_V / ramp_V_s, e.top_V);
    const int halves = e.split_delay_s > 0.0 ? 2 : 1;
    const double drop = e.drop_V / halves, unload = e.unload_V / halves, t0 = t[n - 1];
    for (int i = 0; i < halves; ++i) {
      const double start = t0 + i * e.split_delay_s;
      if (start > t[n - 1]) add(start, u[n - 1]);
      add(t[n - 1] + drop / e.slew_V_s, u[n - 1] - drop);
      if (unload > 0.0) add(t[n - 1] + unload / e.slew_V_s, u[n - 1] + unload);
    }
  }
  void add(double tk, double uk) {
    t[n] = tk;
    u[n] = uk;
    ++n;
  }
  double edge_start_s() const { return t[1]; }
  double at(double time) const {
    if (time >= t[n - 1]) return u[n - 1];
    std::size_t k = 1;
    while (time > t[k]) ++k;
    return u[k - 1] + (u[k] - u[k - 1]) * (time - t[k - 1]) / (t[k] - t[k - 1]);
  }
  /// The segment from `from` to `from` + h, with the drive's corners inside it.
  stickslip::DriveSegment segment(double from, double h) const {
    stickslip::DriveSegment s = stickslip::DriveSegment::to(at(from + h));
    for (std::size_t k = 1; k < n; ++k)
      if (t[k] > from && t[k] < from + h) s.add_corner((t[k] - from) / h, u[k]);
    return s;
  }
};

}  // namespace

EdgeDip run_edge(const stickslip::ActuatorModel& model, const EdgeCase& edge) {
  check(edge);
  const auto& p = model.params();
  const double g = p.pe.static_gain_m_V;
  const double r = edge.ramp_m_s / g;  // the ramp's rate: the slider's speed while it sticks [V/s]
  const EdgeDrive d(edge, r);
  const double t_edge = d.edge_start_s();

  stickslip::ActuatorState s = model.initial_state();
  model.set_operating_point(s, edge.drop_V, r / edge.drop_V, stickslip::Direction::kForward);
  const double h = model.dt_s();
  const double t_end = t_edge + edge.window_s;
  const auto steps = static_cast<long>(std::ceil(t_end / h));
  EdgeDip out;
  out.edge = edge;
  out.edge_s = edge.drop_V / edge.slew_V_s;
  out.z_ba_m = s.z_ba_m;
  out.pe_travel_m = g * edge.drop_V;
  double x0 = std::nan(""), low = 0.0, tail_sum = 0.0;
  long tail_n = 0;
  for (long k = 0; k < steps; ++k) {
    const double t = static_cast<double>(k) * h;
    if (t <= t_edge && t + h > t_edge) x0 = model.slider_position(s);  // the grid point before it
    model.step(s, d.segment(t, h));
    if (s.diverged) throw ComputationFailed(fmt::format("the model diverged at t = {:g} s", t + h));
    if (std::isnan(x0)) continue;
    const double dx = model.slider_position(s) - x0;
    if (dx < low) {
      low = dx;
      out.dip_at_s = t + h - t_edge;
    }
    if (t + h > t_end - 1e-3) {
      tail_sum += dx;
      ++tail_n;
    }
  }
  out.dip_m = -low;
  out.net_m = tail_n > 0 ? tail_sum / static_cast<double>(tail_n) : 0.0;
  out.overshoot_m = out.dip_m + out.net_m;
  return out;
}

PowerFit fit_power(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < std::min(x.size(), y.size()); ++i) {
    if (!(x[i] > 0.0 && y[i] > 0.0)) continue;
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
    ++n;
  }
  PowerFit f;
  f.points = n;
  const double den = n * sxx - sx * sx;
  if (n < 2 || !(std::abs(den) > 0.0)) {
    f.exponent = f.factor = std::nan("");
    return f;
  }
  f.exponent = (n * sxy - sx * sy) / den;
  f.factor = std::exp((sy - f.exponent * sx) / n);
  return f;
}

namespace {

PowerFit fit_dips(const std::vector<EdgeDip>& dips, double (*x_of)(const EdgeDip&)) {
  std::vector<double> x, y;
  for (const auto& d : dips) {
    x.push_back(x_of(d));
    y.push_back(d.dip_m);
  }
  return fit_power(x, y);
}

double drop_of(const EdgeDip& d) { return d.edge.drop_V; }
double duration_of(const EdgeDip& d) { return d.edge_s; }

}  // namespace

EdgeStudy run_edge_study(const stickslip::ActuatorModel& model,
                         const std::function<void(std::size_t, std::size_t)>& progress) {
  // The tracking controller's edge: 31.62..100 V (motion/tracking_controller.h), unloaded by 49.16 V.
  const EdgeCase tracking;
  constexpr double kUnload = 49.16 / 68.38;  // its unloading, as a fraction of the drop
  const std::vector<double> drops{2.0, 4.0, 8.0, 16.0, 32.0, 48.0, 68.38, 100.0};
  const std::vector<double> slews{0.125e6, 0.25e6, 0.5e6, 1e6, 2e6, 4e6, 8e6};
  const std::vector<double> speeds{10e-6, 50e-6, 100e-6, 200e-6, 400e-6};
  const std::vector<double> tops{50.0, 70.0, 85.0, 100.0};
  std::vector<double> delays;
  for (int i = 0; i < 61; ++i) delays.push_back(60e-6 + 20e-6 * i);
  const std::size_t total = 2 * drops.size() + 2 * slews.size() + speeds.size() + tops.size() + delays.size();
  std::size_t done = 0;
  const auto run = [&](EdgeCase e) {
    EdgeDip d = run_edge(model, e);
    if (progress) progress(++done, total);
    return d;
  };
  EdgeStudy st;
  for (double v : drops) {
    EdgeCase e = tracking;
    e.drop_V = v;
    st.drop_sweep.push_back(run(e));
    e.unload_V = kUnload * v;
    st.drop_sweep_unloaded.push_back(run(e));
  }
  for (double s : slews) {
    EdgeCase e = tracking;
    e.slew_V_s = s;
    st.slew_sweep.push_back(run(e));
    e.unload_V = kUnload * e.drop_V;
    st.slew_sweep_unloaded.push_back(run(e));
  }
  for (double v : speeds) {
    EdgeCase e = tracking;
    e.ramp_m_s = v;
    st.speed_sweep.push_back(run(e));
  }
  for (double top : tops) {
    EdgeCase e = tracking;
    e.top_V = top;
    e.drop_V = std::min(e.drop_V, top);
    st.top_sweep.push_back(run(e));
  }
  for (double delay : delays) {
    EdgeCase e = tracking;
    e.unload_V = kUnload * e.drop_V;
    e.split_delay_s = delay;
    st.split_sweep.push_back(run(e));
  }
  st.least_split = *std::min_element(st.split_sweep.begin(), st.split_sweep.end(),
                                     [](const EdgeDip& a, const EdgeDip& b) { return a.dip_m < b.dip_m; });
  // The fits over ΔV of 8 V and more (below, the dip is a few tens of nanometres and the PE's
  // own ringing weighs in it).
  std::vector<EdgeDip> slipping;
  std::vector<EdgeDip> slipping_unloaded;
  for (std::size_t i = 0; i < drops.size(); ++i)
    if (drops[i] >= 8.0) {
      slipping.push_back(st.drop_sweep[i]);
      slipping_unloaded.push_back(st.drop_sweep_unloaded[i]);
    }
  st.dip_vs_drop = fit_dips(slipping, drop_of);
  st.dip_vs_drop_unloaded = fit_dips(slipping_unloaded, drop_of);
  st.dip_vs_duration = fit_dips(st.slew_sweep, duration_of);
  st.dip_vs_duration_unloaded = fit_dips(st.slew_sweep_unloaded, duration_of);
  st.z_ba_m = run_edge(model, tracking).z_ba_m;
  const double p = st.dip_vs_drop.exponent, q = st.dip_vs_duration.exponent;
  if (p >= 1.5 && q > 0.5)
    st.mechanism = "drag";
  else if (std::abs(p) < 0.3)
    st.mechanism = "pre-sliding";
  else if (p >= 0.7 && p <= 1.3 && std::abs(q) < 0.3)
    st.mechanism = "recoil";
  else
    st.mechanism = "mixed";
  return st;
}

}  // namespace mc::studies

#include "microcobot/studies/tracking_run.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "microcobot/core/error.h"
#include "microcobot/motion/closed_loop.h"

namespace mc::studies {

using stickslip::ActuatorModel;
using stickslip::ActuatorState;

std::string to_string(TrackerKind k) {
  switch (k) {
    case TrackerKind::kTracking:
      return "tracking";
    case TrackerKind::kHybrid:
      return "hybrid";
    case TrackerKind::kThesisPid:
      return "thesis-pid";
  }
  return "tracking";
}

TrackerKind parse_tracker_kind(const std::string& name, const std::string& field) {
  for (auto k : {TrackerKind::kTracking, TrackerKind::kHybrid, TrackerKind::kThesisPid})
    if (name == to_string(k)) return k;
  throw InvalidParams(field, "one of tracking, hybrid, thesis-pid (got '" + name + "')");
}

TrackerSetup tracker_setup(const motion::ControlParams& p) {
  TrackerSetup su{p.tracking, p.position, p.baseline, p.sensor};
  su.hybrid.scan_velocity_m_s = std::max(su.hybrid.scan_velocity_m_s, 1.5 * p.limits.max_velocity_m_s);
  su.hybrid.scan_acceleration_m_s2 =
      std::max(su.hybrid.scan_acceleration_m_s2, 1.5 * p.limits.max_acceleration_m_s2);
  return su;
}

TrackingMetrics tracking_metrics(const std::vector<double>& ref, const std::vector<double>& x,
                                 const std::vector<char>& moving, double tick_s) {
  require(ref.size() == x.size() && moving.size() == x.size() && !x.empty(), "records",
          "need equal, non-empty lengths");
  TrackingMetrics m;
  double sq = 0.0, sq_all = 0.0;
  long n = 0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double e = x[k] - ref[k];
    sq_all += e * e;
    if (!moving[k]) continue;
    sq += e * e;
    m.max_error_m = std::max(m.max_error_m, std::abs(e));
    ++n;
  }
  m.rms_error_m = n > 0 ? std::sqrt(sq / static_cast<double>(n)) : 0.0;
  m.rms_all_m = std::sqrt(sq_all / static_cast<double>(x.size()));
  m.final_error_m = std::abs(x.back() - ref.back());
  // Lag: the shift (0 .. 50 ms, whole ticks, then a parabola through the best three) that
  // minimises the RMS of x(t) - r(t - tau) over the moving ticks.
  if (n > 10) {
    const long max_shift = std::min<long>(std::lround(0.05 / tick_s), static_cast<long>(x.size()) / 2);
    auto cost = [&](long s) {
      double c = 0.0;
      long cnt = 0;
      for (std::size_t k = static_cast<std::size_t>(s); k < x.size(); ++k) {
        if (!moving[k]) continue;
        const double e = x[k] - ref[k - static_cast<std::size_t>(s)];
        c += e * e;
        ++cnt;
      }
      return cnt > 0 ? c / static_cast<double>(cnt) : 1e300;
    };
    long best = 0;
    double cb = cost(0);
    // Coarse to fine: the cost is smooth in the shift for smooth references.
    for (long s = 1; s <= max_shift; ++s) {
      const double c = cost(s);
      if (c < cb) {
        cb = c;
        best = s;
      } else if (c > 4.0 * cb && s > best + 20) {
        break;
      }
    }
    double frac = 0.0;
    if (best > 0 && best < max_shift) {
      const double cm = cost(best - 1), cp = cost(best + 1);
      const double den = cm - 2.0 * cb + cp;
      if (den > 0.0) frac = std::clamp(0.5 * (cm - cp) / den, -0.5, 0.5);
    }
    m.lag_s = (static_cast<double>(best) + frac) * tick_s;
  }
  return m;
}

namespace {

ActuatorState start_state(const ActuatorModel& model, double start_m) {
  const double half = 0.5 * model.params().slider.stroke_m;
  require(std::isfinite(start_m) && std::abs(start_m) <= half, "start_m", "must lie within the stroke",
          start_m);
  ActuatorState s = model.initial_state();
  s.x2_m = {start_m, start_m};
  return s;
}

/// The three trackers behind one interface for the loop below.
struct Tracker {
  virtual ~Tracker() = default;
  virtual void update(const motion::ReferenceSample& r, double x) noexcept = 0;
  virtual stickslip::DriveSegment next_drive(double dt) noexcept = 0;
  virtual void operating_point(double& a, double& f, stickslip::Direction& d) const noexcept = 0;
  virtual long edges() const noexcept = 0;
  /// Power-up done: the reference may move.
  virtual bool ready() const noexcept { return true; }
};

struct NewTracker final : Tracker {
  motion::TrackingController c;
  NewTracker(const TrackerSetup& s, const ActuatorModel& m, const motion::StepMap& map, double x0)
      : c(s.tracking, m.params(), map) {
    c.reset(x0, m.initial_state().u_V);  // where the plant's drive starts
  }
  void update(const motion::ReferenceSample& r, double x) noexcept override {
    c.set_reference(r);
    c.update(x);
  }
  stickslip::DriveSegment next_drive(double dt) noexcept override { return c.next_drive(dt); }
  void operating_point(double& a, double& f, stickslip::Direction& d) const noexcept override {
    a = c.operating_point().amplitude_V;
    f = c.operating_point().frequency_Hz;
    d = c.operating_point().direction;
  }
  /// The steps of the move: those the hold took at power-up before ready() are not counted.
  long edges() const noexcept override { return static_cast<long>(c.edges()) - edges_at_ready; }
  bool ready() const noexcept override {
    if (!c.ready()) edges_at_ready = static_cast<long>(c.edges());
    return c.ready();
  }
  mutable long edges_at_ready = 0;
};

struct HybridTracker final : Tracker {
  motion::PositionController c;
  HybridTracker(const TrackerSetup& s, const ActuatorModel& m, const motion::StepMap& map)
      : c(s.hybrid, m.params(), map) {}
  void update(const motion::ReferenceSample& r, double x) noexcept override {
    c.set_target(r.x_m, r.v_m_s);
    c.update(x);
  }
  stickslip::DriveSegment next_drive(double dt) noexcept override { return c.next_drive(dt); }
  void operating_point(double& a, double& f, stickslip::Direction& d) const noexcept override {
    a = c.generator().amplitude_V();
    f = c.generator().frequency_Hz();
    d = c.generator().direction();
  }
  long edges() const noexcept override { return static_cast<long>(c.generator().periods()); }
};

struct PidTracker final : Tracker {
  motion::BaselinePositionController c;
  bool started = false;
  PidTracker(const TrackerSetup& s, const ActuatorModel& m)
      : c(s.pid, motion::BaselineKind::kThesisPid, m.params().drive.slew_rate_V_s) {}
  void update(const motion::ReferenceSample& r, double x) noexcept override {
    if (!started) {
      c.set_target(r.x_m, x);
      started = true;
    }
    c.track(r.x_m);
    c.update(x);
  }
  stickslip::DriveSegment next_drive(double dt) noexcept override { return c.next_drive(dt); }
  void operating_point(double& a, double& f, stickslip::Direction& d) const noexcept override {
    a = c.generator().amplitude_V();
    f = c.generator().frequency_Hz();
    d = c.generator().direction();
  }
  long edges() const noexcept override { return static_cast<long>(c.generator().periods()); }
};

}  // namespace

namespace {
std::unique_ptr<Tracker> make_tracker(TrackerKind kind, const TrackerSetup& setup, const ActuatorModel& model,
                                      const motion::StepMap& map, double start_m) {
  switch (kind) {
    case TrackerKind::kTracking:
      return std::make_unique<NewTracker>(setup, model, map, start_m);
    case TrackerKind::kHybrid:
      return std::make_unique<HybridTracker>(setup, model, map);
    case TrackerKind::kThesisPid:
      return std::make_unique<PidTracker>(setup, model);
  }
  return nullptr;
}
}  // namespace

PathRecord run_path(const ActuatorModel& model, const motion::StepMap& map, TrackerKind kind,
                    const TrackerSetup& setup, const motion::PathGenerator& path, double hold_s,
                    int max_records, const PathLeadIn& lead_in) {
  require_non_negative(hold_s, "hold_s");
  require(max_records >= 10, "max_records", "must be >= 10", max_records);
  require_non_negative(lead_in.dwell_s, "lead_in.dwell_s");
  const double lead_s = lead_in.path ? lead_in.path->duration_s() + lead_in.dwell_s : 0.0;
  if (lead_in.path) {
    require((lead_in.path->sample(lead_in.path->duration_s()).x_m - path.sample(0.0).x_m).norm() < 1e-12,
            "lead_in.path", "must end where the path starts");
  }
  // The reference at time t since the axes were ready: the lead-in, its rest, then the path.
  const auto reference = [&](double t) {
    if (!lead_in.path) return path.sample(t);
    if (t < lead_in.path->duration_s()) return lead_in.path->sample(t);
    if (t < lead_s) return path.sample(0.0);
    return path.sample(t - lead_s);
  };
  const int ratio = motion::steps_per_tick(model, 10000.0);
  const double tick = static_cast<double>(ratio) * model.dt_s();
  const double duration = lead_s + path.duration_s() + hold_s;
  const long ticks = std::lround(duration / tick);
  const long every = std::max(1L, ticks / max_records);
  const motion::PathSample p0 = reference(0.0);
  std::array<std::unique_ptr<Tracker>, 3> tr;
  std::array<ActuatorState, 3> st;
  std::vector<motion::PositionSensor> sensors;
  for (int i = 0; i < 3; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    tr[iu] = make_tracker(kind, setup, model, map, p0.x_m[i]);
    st[iu] = start_state(model, p0.x_m[i]);
    auto sp = setup.sensor;
    sp.seed += i;  // the XYZ stage's per-axis noise stream
    sensors.emplace_back(sp);
  }
  PathRecord rec;
  double sq_dev = 0.0, sq_err = 0.0;
  long n = 0;
  const double dt = model.dt_s();
  Eigen::Vector3d x = p0.x_m, r = p0.x_m;
  // Power-up: the reference rests at its start until every axis is ready (bounded: 0.1 s).
  long wait = 0;
  const long max_wait = std::lround(0.1 / tick);
  for (long k = 0; k < ticks + wait; ++k) {
    const bool ready = std::all_of(tr.begin(), tr.end(), [](const auto& t) { return t->ready(); });
    if (!ready && k == wait && wait < max_wait) ++wait;
    const double t = static_cast<double>(k - wait) * tick;
    motion::PathSample ps = k < wait ? p0 : reference(t);
    if (k < wait) ps.v_m_s.setZero(), ps.a_m_s2.setZero();
    for (int i = 0; i < 3; ++i) {
      const auto iu = static_cast<std::size_t>(i);
      ActuatorState& s = st[iu];
      tr[iu]->update(motion::ReferenceSample{ps.x_m[i], ps.v_m_s[i], ps.a_m_s2[i]},
                     sensors[iu].measure(model.slider_position(s)));
      double a = 0.0, f = 1000.0;
      stickslip::Direction d = stickslip::Direction::kForward;
      tr[iu]->operating_point(a, f, d);
      model.set_operating_point(s, a, f, d);
      for (int j = 0; j < ratio; ++j) model.step(s, tr[iu]->next_drive(dt));
      if (s.diverged) {
        throw ComputationFailed("closed-loop simulation diverged (NaN/Inf) at t = " + std::to_string(s.t_s) +
                                " s");
      }
      x[i] = model.slider_position(s);
    }
    r = ps.x_m;
    const bool measured = k >= wait && t >= lead_s && t <= lead_s + path.duration_s();
    const double dev = measured ? path.distance_to_path(x) : 0.0;
    const double err = (x - r).norm();
    if (measured) {
      sq_dev += dev * dev;
      sq_err += err * err;
      ++n;
      rec.metrics.max_deviation_m = std::max(rec.metrics.max_deviation_m, dev);
      rec.metrics.max_error_m = std::max(rec.metrics.max_error_m, err);
    }
    if (k % every == 0) {
      rec.t_s.push_back(static_cast<double>(k + 1) * tick);
      rec.deviation_m.push_back(dev);
      for (std::size_t i = 0; i < 3; ++i) {
        rec.x_m[i].push_back(x[static_cast<Eigen::Index>(i)]);
        rec.ref_m[i].push_back(r[static_cast<Eigen::Index>(i)]);
      }
    }
  }
  rec.metrics.rms_deviation_m = std::sqrt(sq_dev / static_cast<double>(std::max(1L, n)));
  rec.metrics.rms_error_m = std::sqrt(sq_err / static_cast<double>(std::max(1L, n)));
  rec.metrics.final_error_m = (x - r).norm();
  for (const auto& t : tr) rec.metrics.edges += t->edges();
  return rec;
}

TrackingRecord run_tracker(const ActuatorModel& model, const motion::StepMap& map, TrackerKind kind,
                           const TrackerSetup& setup, double start_m, const ReferenceFn& reference,
                           double duration_s, int max_records, double metrics_from_s,
                           motion::IterativeLearning* learning) {
  require_positive(duration_s, "duration_s");
  require(learning == nullptr || kind == TrackerKind::kTracking, "learning",
          "applies to the tracking controller only");
  require(max_records >= 10, "max_records", "must be >= 10", max_records);
  require(metrics_from_s >= 0.0 && metrics_from_s < duration_s, "metrics_from_s",
          "must lie in [0, duration_s)", metrics_from_s);
  std::unique_ptr<Tracker> tr = make_tracker(kind, setup, model, map, start_m);
  motion::PositionSensor sensor(setup.sensor);
  ActuatorState s = start_state(model, start_m);
  const int ratio = motion::steps_per_tick(model, 10000.0);
  const double tick = static_cast<double>(ratio) * model.dt_s();
  const long ticks = std::lround(duration_s / tick);
  const long every = std::max(1L, ticks / max_records);
  std::vector<double> ref, xs;
  std::vector<char> moving;
  ref.reserve(static_cast<std::size_t>(ticks));
  xs.reserve(static_cast<std::size_t>(ticks));
  moving.reserve(static_cast<std::size_t>(ticks));
  TrackingRecord rec;
  const double dt = model.dt_s();
  // Power-up: the reference rests at start_m until the tracker is ready (bounded: 0.1 s); its
  // clock starts then.
  long wait = 0;
  const long max_wait = std::lround(0.1 / tick);
  for (long k = 0; k < ticks + wait; ++k) {
    if (!tr->ready() && k == wait && wait < max_wait) ++wait;
    const double t_ref = static_cast<double>(k - wait) * tick;
    const motion::ReferenceSample r =
        k < wait ? motion::ReferenceSample{start_m, 0.0, 0.0} : reference(t_ref, tick);
    const double measured = sensor.measure(model.slider_position(s));
    motion::ReferenceSample followed = r;
    if (learning != nullptr && k >= wait) {
      // Tick i = k - wait of the reference: the error after tick i - 1's drive, then tick i's correction.
      const long i = k - wait;
      if (i > 0) learning->record(i - 1, measured - ref.back());
      followed.x_m += learning->feedforward(i);
    }
    tr->update(followed, measured);
    double a = 0.0, f = 1000.0;
    stickslip::Direction d = stickslip::Direction::kForward;
    tr->operating_point(a, f, d);
    model.set_operating_point(s, a, f, d);
    double u = 0.0;
    for (int i = 0; i < ratio; ++i) {
      const stickslip::DriveSegment seg = tr->next_drive(dt);
      model.step(s, seg);
      u = seg.end_V;
    }
    if (s.diverged) {
      throw ComputationFailed("closed-loop simulation diverged (NaN/Inf) at t = " + std::to_string(s.t_s) +
                              " s");
    }
    const double x = model.slider_position(s);
    ref.push_back(r.x_m);
    xs.push_back(x);
    moving.push_back(k >= wait && t_ref >= metrics_from_s && r.v_m_s != 0.0 ? 1 : 0);
    if (k % every == 0) {
      rec.t_s.push_back(static_cast<double>(k + 1) * tick);
      rec.ref_m.push_back(r.x_m);
      rec.x_m.push_back(x);
      rec.u_V.push_back(u);
    }
  }
  rec.metrics = tracking_metrics(ref, xs, moving, tick);
  rec.metrics.edges = tr->edges();
  return rec;
}

}  // namespace mc::studies

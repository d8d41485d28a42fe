#include "microcobot/cell/person_model.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"
#include "microcobot/dsp/butterworth.h"

namespace mc::cell {

void PersonParams::validate() const {
  require_non_negative(reaction_time_s, "reaction_time_s");
  require_non_negative(display_delay_s, "display_delay_s");
  require_non_negative(fitts_a_s, "fitts_a_s");
  require_positive(fitts_b_s_per_bit, "fitts_b_s_per_bit");
  require(endpoint_sd_fraction >= 0.0 && endpoint_sd_fraction < 0.5, "endpoint_sd_fraction",
          "must be within [0, 0.5)", endpoint_sd_fraction);
  require_non_negative(tremor_rms_m, "tremor_rms_m");
  require_positive(tremor_low_Hz, "tremor_low_Hz");
  require(tremor_high_Hz > tremor_low_Hz, "tremor_high_Hz", "must be above tremor_low_Hz", tremor_high_Hz);
  require_non_negative(vision_sd_m, "vision_sd_m");
  require_positive(feel_contact_N, "feel_contact_N");
  require_positive(stage_pace_m_s, "stage_pace_m_s");
}

double PersonParams::movement_time_s(double d, double w) const noexcept {
  return fitts_a_s + fitts_b_s_per_bit * std::log2(d / w + 1.0);
}

void Reach::reset(const Eigen::Vector2d& at, double t_s) noexcept {
  x0_ = x1_ = at;
  t0_ = t_s;
  duration_ = 0.0;
}

bool Reach::aim(const Eigen::Vector2d& error, double tolerance, double t_s, double max_speed,
                double width) noexcept {
  // The last movement's end is seen after the display's delay, and acted on a reaction later.
  if (!ready(t_s) || !error.allFinite()) return false;
  const double d = error.norm();
  if (d <= tolerance) return true;
  const double sd = p_.endpoint_sd_fraction * d;
  x0_ = x1_;
  // One draw per statement (a call's arguments have no order, GCC's was y first): a seed gives the
  // same person whatever the compiler.
  const double miss_y = rng_.normal(0.0, sd), miss_x = rng_.normal(0.0, sd);
  x1_ = x0_ + error + Eigen::Vector2d(miss_x, miss_y);
  t0_ = t_s;
  duration_ = std::max(p_.movement_time_s(d, std::max(tolerance, width)), 1.875 * d / max_speed);
  ++count_;
  return false;
}

void Reach::move(const Eigen::Vector2d& goal, double duration_s, double t_s) noexcept {
  x0_ = position(t_s);
  x1_ = goal;
  t0_ = t_s;
  duration_ = std::max(duration_s, 1e-3);
}

Eigen::Vector2d Reach::position(double t_s) const noexcept {
  if (duration_ <= 0.0 || t_s >= t0_ + duration_) return x1_;
  const double s = std::clamp((t_s - t0_) / duration_, 0.0, 1.0);
  const double shape = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);  // Flash and Hogan's
  return x0_ + (x1_ - x0_) * shape;
}

Eigen::Vector2d Reach::velocity(double t_s) const noexcept {
  if (duration_ <= 0.0 || t_s >= t0_ + duration_ || t_s < t0_) return Eigen::Vector2d::Zero();
  const double s = (t_s - t0_) / duration_;
  const double rate = 30.0 * s * s * (1.0 - s) * (1.0 - s) / duration_;  // d shape / dt
  return (x1_ - x0_) * rate;
}

namespace {

dsp::Sos tremor_band(const PersonParams& p, double rate_Hz) {
  dsp::Sos sos = dsp::butter(4, p.tremor_low_Hz, rate_Hz, dsp::FilterType::kHighPass);
  const dsp::Sos low = dsp::butter(4, p.tremor_high_Hz, rate_Hz, dsp::FilterType::kLowPass);
  sos.insert(sos.end(), low.begin(), low.end());
  return sos;
}

}  // namespace

Tremor::Tremor(const PersonParams& params, double rate_Hz, std::uint64_t seed)
    : rng_(seed), x_(tremor_band(params, rate_Hz)), y_(tremor_band(params, rate_Hz)) {
  params.validate();
  require(params.tremor_high_Hz < 0.45 * rate_Hz, "tremor_high_Hz",
          "must be below the operator rate's Nyquist", params.tremor_high_Hz);
  // The band-pass' noise gain: the energy of its impulse response (10 s: it has long decayed).
  dsp::SosFilter probe(tremor_band(params, rate_Hz));
  double energy = 0.0;
  for (int i = 0; i < static_cast<int>(10.0 * rate_Hz); ++i) {
    const double h = probe.process(i == 0 ? 1.0 : 0.0);
    energy += h * h;
  }
  gain_ = params.tremor_rms_m / std::sqrt(energy);
}

Eigen::Vector2d Tremor::next() noexcept {
  return {x_.process(gain_ * rng_.normal()), y_.process(gain_ * rng_.normal())};
}

}  // namespace mc::cell

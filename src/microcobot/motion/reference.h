#pragma once
/// @file
/// Position references for trajectory tracking under velocity and acceleration limits:
///  - ReferenceLimiter: turns any setpoint stream (e.g. setpoints at 1 kHz) into a reference whose
///    velocity and acceleration never exceed the limits and that stops on the setpoint without
///    overshoot (v_cmd = sign(e) min(v_max, sqrt(2 a_max |e|)), then |dv| <= a_max dt);
///    a single setpoint gives the trapezoidal (or triangular) move;
///  - SineReference: x0 + A sin(2 pi f t), checked against the limits.
/// step() / at() never allocate.

namespace mc::motion {

struct MotionLimits {
  double max_velocity_m_s = 200e-6;     ///< default: 200 um/s, within one axis' stepping speed
  double max_acceleration_m_s2 = 2e-3;  ///< default: 2 mm/s^2

  template <class V>
  void visit(V& v) {
    v("max_velocity_m_s", max_velocity_m_s);
    v("max_acceleration_m_s2", max_acceleration_m_s2);
  }
  void validate() const;
};

struct ReferenceSample {
  double x_m = 0.0;
  double v_m_s = 0.0;
  double a_m_s2 = 0.0;
};

class ReferenceLimiter {
 public:
  explicit ReferenceLimiter(const MotionLimits& limits, double x0_m = 0.0);
  /// Advances by dt toward `setpoint_m`. Never allocates.
  ReferenceSample step(double setpoint_m, double dt_s) noexcept;
  ReferenceSample state() const noexcept { return s_; }
  void reset(double x0_m) noexcept { s_ = ReferenceSample{x0_m, 0.0, 0.0}; }

 private:
  MotionLimits lim_;
  ReferenceSample s_;
};

class SineReference {
 public:
  /// Throws InvalidParams if A (2 pi f) > v_max or A (2 pi f)^2 > a_max.
  SineReference(double x0_m, double amplitude_m, double frequency_Hz, const MotionLimits& limits);
  ReferenceSample at(double t_s) const noexcept;

 private:
  double x0_, a_, w_;
};

/// Duration of a trapezoidal (or triangular) move of `distance_m` under `limits` [s].
double trapezoid_duration_s(double distance_m, const MotionLimits& limits);

}  // namespace mc::motion

#pragma once
/// @file
/// A discrete PID with output limits, conditional-integration anti-windup and a first-order
/// filter on the derivative (the controller of thesis §2.7, Fig. 2.18, acting on the sawtooth
/// amplitude).

namespace mc::motion {

struct PidParams {
  double kp = 0.0;                   ///< proportional gain (output per unit of error)
  double ki = 0.0;                   ///< integral gain (per second)
  double kd = 0.0;                   ///< derivative gain (seconds)
  double derivative_filter_s = 0.0;  ///< time constant of the derivative filter (0 = none)
  double out_min = 0.0;              ///< the output's lower bound (the integrator stops there: anti-windup)
  double out_max = 100.0;            ///< its upper bound

  template <class V>
  void visit(V& v) {
    v("kp", kp);
    v("ki", ki);
    v("kd", kd);
    v("derivative_filter_s", derivative_filter_s);
    v("out_min", out_min);
    v("out_max", out_max);
  }
  void validate() const;
};

class Pid {
 public:
  explicit Pid(const PidParams& p = {});
  /// out = clamp(ff + kp e + I + kd de/dt); I integrates only while the output is not saturated
  /// in the direction of e, or when `freeze` (e.g. at an end stop). Never allocates.
  double update(double error, double dt_s, double feedforward = 0.0, bool freeze = false) noexcept;
  void reset(double integral = 0.0) noexcept;
  double integral() const noexcept { return i_; }
  const PidParams& params() const { return p_; }

 private:
  PidParams p_;
  double i_ = 0.0, e_prev_ = 0.0, d_ = 0.0;
  bool first_ = true;
};

}  // namespace mc::motion

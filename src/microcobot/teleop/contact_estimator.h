#pragma once
/// @file
/// The slave's estimate of the contact it touches, for model-mediated teleoperation (Mitra and
/// Niemeyer, "Model-mediated telemanipulation", SPIE 6906, 2008): a wall at x_w of
/// stiffness k,
///   f_e = k (x_s - x_w)  while f_e > contact threshold,                              (1)
/// fitted by exponentially weighted least squares over the contact samples (recursive least
/// squares with forgetting factor lambda, Ljung and Soderstrom, "Theory and Practice of Recursive
/// Identification", 1983, ch. 2; here in its moment form, which is the same estimate):
///   k   = cov_w(x_s, f_e) / var_w(x_s),    x_w = mean_w(x_s) - mean_w(f_e) / k        (2)
/// with weights lambda^(n-i). k is re-fitted only while the samples spread over more than
/// `min_spread_m` (std of x_s): a slave that rests in the contact carries no information about
/// the stiffness, and (2) would divide by ~0; x_w is re-fitted with the k held. Free space is
/// information too: a slave that reached x_s without a contact force puts the wall beyond x_s.
/// The estimate starts from the prior (the microworld's geometry and the material's nominal
/// stiffness). update() is plain arithmetic: no allocation, no branch on the delay.

namespace mc::teleop {

/// A contact model: the wall's position and stiffness, in the master's units.
struct ContactModel {
  double sent_s = 0.0;  ///< when the slave sent it (the link emulator's stamp)
  double wall_m = 0.0;
  double stiffness_N_m = 0.0;
};

struct ContactEstimatorParams {
  double contact_threshold_N = 0.02;  ///< a contact force above this is a contact sample
  double forgetting = 0.999;          ///< lambda per sample: ~1/(1 - lambda) samples of memory
  double min_spread_m = 2e-5;         ///< std of x_s over the window before k is re-fitted
  void validate() const;
};

class ContactEstimator {
 public:
  /// Throws InvalidParams. `prior` is the model before any contact (geometry, nominal stiffness).
  ContactEstimator(const ContactEstimatorParams& p, const ContactModel& prior);
  /// One sample of the slave's position and measured contact force. Never allocates.
  void update(double x_s, double f_e) noexcept;
  const ContactModel& model() const { return model_; }
  bool in_contact() const { return in_contact_; }

 private:
  ContactEstimatorParams p_;
  ContactModel model_;
  bool in_contact_ = false, have_origin_ = false;
  // Weighted moments of (x_s - x0, f_e) over the contact samples; x0 = the first contact's x_s
  // keeps the sums free of cancellation (x_s ~ 2e-2 m, spreads ~1e-4 m).
  double x0_ = 0.0, w_ = 0.0, sx_ = 0.0, sf_ = 0.0, sxx_ = 0.0, sxf_ = 0.0;
};

}  // namespace mc::teleop

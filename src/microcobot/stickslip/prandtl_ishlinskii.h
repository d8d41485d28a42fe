#pragma once
/// @file
/// Prandtl-Ishlinskii static hysteresis H(U) (thesis Fig. 2.6, eq. 2.5) and its exact inverse.
///
/// H is a weighted sum of n play (backlash) operators of half-width r_i (bandwidth bw_i = 2 r_i):
///   y_i(t) = max(U - r_i, min(U + r_i, y_i(t-))),   H(U) = sum_i w_i y_i.
/// H is rate independent: its output depends on the input path, never on its speed. The output
/// is in volts (an "equivalent voltage"); the PE's static gain (m/V) turns it into metres.

#include <vector>

namespace mc::stickslip {

/// Thresholds r_i [V] (strictly increasing, r_0 = 0 allowed) and weights w_i [-] of the PI model.
struct PiParams {
  std::vector<double> thresholds_V;  ///< r_i, half bandwidths of the backlash operators
  std::vector<double> weights;       ///< w_i; w_0 > 0 and every partial sum > 0 (invertibility)

  template <class V>
  void visit(V& v) {
    v("thresholds_V", thresholds_V);
    v("weights", weights);
  }
  /// Throws mc::InvalidParams naming the field (sizes, ordering, invertibility).
  void validate() const;
  std::size_t size() const { return thresholds_V.size(); }
};

/// Default PI model: n = 35 operators (thesis §2.5.2.2), thresholds on a non-uniform (quadratic)
/// partition of 0..50 V, a linear weight w_0 and geometrically decaying others (the thesis gives
/// no values: chosen, docs/parameters.md),
/// scaled so that the loading curve maps 100 V to 100 V.
PiParams default_pi_params(int n = 35);

/// The operator states y_i. Plain data, sized once by make_state().
struct PiState {
  std::vector<double> y;
};

/// A state in which every operator is relaxed at input `u0` (y_i = clamp(0, u0 - r_i, u0 + r_i) with
/// history starting at 0 V).
PiState make_pi_state(const PiParams& p, double u0 = 0.0);

/// Advances the operators to input `u` and returns H(U). Never allocates.
double pi_update(const PiParams& p, PiState& s, double u) noexcept;

/// H(U) that the operators would output at input `u`, without committing (for ODE stages).
double pi_peek(const PiParams& p, const PiState& s, double u) noexcept;

/// The input u in [u_lo, u_hi] at which pi_peek(p, s, u) = h, clamped to the interval's ends when
/// h lies outside their outputs: the voltage that puts the element at a given extension from its
/// present state (the controllers' scanning feedforward). pi_peek is continuous, strictly
/// increasing (w_0 > 0) and piecewise linear in u from any state (each operator's output follows
/// u or holds), so regula falsi (Illinois) lands on the exact root as soon as its bracket lies on
/// one linear piece: a few evaluations where bisection needed 42 (the tracking controller's
/// largest cost in the loop, docs/benchmarks.md). It stops at a zero residual or at the
/// resolution those 40 halvings gave, (u_hi - u_lo) / 2^40. Never allocates.
double pi_peek_inverse(const PiParams& p, const PiState& s, double h, double u_lo, double u_hi) noexcept;

/// The exact inverse PI model (Kuhnen / Krejci): another PI operator whose composition with `p`
/// is the identity, H(H^-1(y)) = y, when both start relaxed at 0.
PiParams pi_inverse(const PiParams& p);

/// The initial loading curve H(U) for a monotone rise from 0: sum_i w_i max(U - r_i, 0).
double pi_loading_curve(const PiParams& p, double u) noexcept;

}  // namespace mc::stickslip

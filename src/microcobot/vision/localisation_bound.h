#pragma once
/// @file
/// The best precision any unbiased estimator can reach for a target's translation in a noisy
/// frame: the Cramér-Rao lower bound (the goal for a tracker: within 2x of it at the
/// frame's SNR; the bound Thompson et al., Biophys. J. 82, 2002, and Mortensen et al., Nat.
/// Methods 7, 2010, give in closed form for a point source, here for any rendered target).
///
/// With the expected grey level mu_k(t) of pixel k when the target is translated by t = (du, dv)
/// and independent noise of variance var_k (shot noise of the photo-electrons and the dark
/// signal, read noise, quantisation: sensor_model.h),
///     F = sum_k (d mu_k/dt)(d mu_k/dt)^T / var_k,     cov(t_hat) >= F^-1,
/// summed over the pixels the estimator sees (its template's ROI). The derivatives are central
/// differences of rendered expected images.

#include <functional>
#include <vector>

#include "microcobot/imaging/camera_params.h"
#include "microcobot/vision/template_tracker.h"

namespace mc::vision {

struct LocalisationBound {
  double sigma_u_px = 0.0;  ///< the bound's standard deviation along the columns
  double sigma_v_px = 0.0;  ///< ... along the rows
};

/// `expected_e(du, dv)`: the expected photo-electrons per pixel (row-major, the sensor's size;
/// Renderer::render_expected) with the target moved by (du, dv) px. `step_px`: the central
/// difference's half step. Throws InvalidInput when the ROI is not inside the sensor or the
/// target gives no information (the Fisher matrix is singular).
LocalisationBound translation_bound(
    const std::function<std::vector<float>(double du_px, double dv_px)>& expected_e,
    const imaging::SensorParams& sensor, double exposure_s, double gain, const imaging::PixelRoi& roi,
    double step_px = 0.05);

}  // namespace mc::vision

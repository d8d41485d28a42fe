#pragma once
/// @file
/// Peak finding in sampled curves (spectra, FRF magnitudes) with sub-sample location by
/// parabolic interpolation through the peak and its two neighbours. On the logarithm of a
/// Hann-windowed power spectrum the parabola locates a resonance or tone to a small fraction
/// of the bin width (the stick-slip modal identification of thesis §2.5.2 needs this).

#include <limits>
#include <span>
#include <vector>

namespace mc::dsp {

struct PeakOptions {
  double min_height = -std::numeric_limits<double>::infinity();  ///< y[i] >= min_height
  double min_prominence = 0.0;     ///< scipy's prominence (height above the higher base)
  std::size_t min_distance = 1;    ///< samples between kept peaks (higher peaks win)
  bool log_interpolation = false;  ///< interpolate on log(y) (requires y > 0 near peaks)
  std::size_t max_peaks = 0;       ///< keep only the highest ones; 0 keeps all
};

struct Peak {
  std::size_t index = 0;  ///< sample of the local maximum
  double position = 0.0;  ///< interpolated fractional index
  double height = 0.0;    ///< interpolated peak value (in y's units, not log)
  double prominence = 0.0;
  double x = 0.0;  ///< position mapped to the x axis (find_peaks_xy), else = position
};

/// Local maxima of y (plateaus count once, at their middle) filtered by `options`, sorted by
/// index. Endpoints are never peaks (as scipy.signal.find_peaks).
std::vector<Peak> find_peaks(std::span<const double> y, const PeakOptions& options = {});

/// find_peaks with positions mapped to a uniformly spaced x axis (e.g. frequencies):
/// Peak::x = x[0] + position * (x[1] - x[0]).
std::vector<Peak> find_peaks_xy(std::span<const double> x, std::span<const double> y,
                                const PeakOptions& options = {});

/// Vertex of the parabola through (-1, ym), (0, y0), (1, yp): offset in (-1, 1) and value.
struct ParabolicVertex {
  double offset;
  double value;
};
ParabolicVertex parabolic_vertex(double ym, double y0, double yp);

}  // namespace mc::dsp

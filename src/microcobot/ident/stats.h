#pragma once
/// @file
/// Descriptive statistics with numpy/scipy.stats conventions (population moments,
/// ddof = 0; biased skewness; Fisher excess kurtosis) and a Gaussian fit of a histogram with
/// its coefficient of determination R^2 (the stick-slip step-size distributions, thesis §2.6).

#include <span>
#include <vector>

namespace mc::ident {

double mean(std::span<const double> x);
/// sqrt(mean(x^2)).
double rms(std::span<const double> x);
/// Population standard deviation (numpy.std, ddof = 0).
double stddev(std::span<const double> x);
/// Biased sample skewness m3 / m2^1.5 (scipy.stats.skew).
double skewness(std::span<const double> x);
/// Excess kurtosis m4 / m2^2 - 3 (scipy.stats.kurtosis, 0 for a Gaussian).
double kurtosis(std::span<const double> x);

/// Equal-width histogram over [lo, hi] (values outside are ignored; hi goes in the last bin).
struct Histogram {
  std::vector<double> centres;
  std::vector<double> counts;
  double width = 0.0;
};
Histogram histogram(std::span<const double> x, std::size_t bins, double lo, double hi);

/// counts ~ amplitude exp(-(x - mean)^2 / (2 sigma^2)).
struct GaussianFit {
  double amplitude = 0.0;
  double mean = 0.0;
  double sigma = 0.0;
  double r2 = 0.0;  ///< 1 - SS_res / SS_tot
};
/// Least-squares Gaussian fit (Levenberg-Marquardt from the moments of the histogram).
/// Throws InvalidParams for fewer than 3 bins or an empty histogram, ComputationFailed when
/// the fit does not converge to finite values.
GaussianFit fit_gaussian(std::span<const double> centres, std::span<const double> counts);

}  // namespace mc::ident

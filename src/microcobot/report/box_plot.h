#pragma once
/// @file
/// Box plots in reports: a figure whose series are groups of samples (one box
/// each, e.g. one per mode of the cell), summarised here as Tukey's box plot so that the page only
/// draws what the library computed (and tests check the numbers, not pixels).

#include <string>
#include <utility>
#include <vector>

#include "microcobot/report/report.h"

namespace mc::report {

/// Tukey's box plot of one group: the quartiles (type 7 interpolation, numpy's default), the
/// whiskers at the most extreme samples within 1.5 IQR of the box, and the samples beyond them.
struct BoxStats {
  std::size_t n = 0;
  double q1 = 0.0, median = 0.0, q3 = 0.0;
  double whisker_low = 0.0, whisker_high = 0.0;
  std::vector<double> outliers;  ///< ascending
};

/// The box of `samples` (at least one, all finite: throws InvalidParams otherwise).
BoxStats box_stats(std::vector<double> samples);

/// A box-plot figure: one box per group (name, samples), drawn left to right in the given order.
/// Each group becomes a series with x = its position (1, 2, ...) and y = its samples, so the
/// figure's CSV keeps every sample; the page draws the boxes (web/report.js).
/// `group_label` names what the groups are (e.g. "Mode"); `value_axis` must be linear.
Figure box_figure(std::string title, std::string caption, std::string group_label, Axis value_axis,
                  std::vector<std::pair<std::string, std::vector<double>>> groups);

}  // namespace mc::report

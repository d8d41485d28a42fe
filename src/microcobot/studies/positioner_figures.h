#pragma once
/// @file
/// The parallel positioner's figures (the full report's part "positioner", and
/// `microcobot positioner workspace --out`): where its workspace ends and why, and how far each
/// rotation turns (motion/parallel_workspace.h).

#include <string>

#include "microcobot/core/csv.h"
#include "microcobot/motion/parallel_workspace.h"
#include "microcobot/report/report.h"

namespace mc::studies {

/// A workspace slice (motion::workspace_slice's table over `s`) as points in its two coordinates
/// (mm, deg), one series per reach code that occurs: the reachable region and, around it, the
/// first check each refused pose fails.
report::Figure workspace_slice_figure(const CsvTable& slice, const motion::SliceSpec& s, std::string title,
                                      std::string caption);

/// The report's part: the default 110.45-size geometry's slices over x-y at the home height and
/// over rx-ry at the home position, and each rotation's travel at home and 4 mm off it.
void positioner_figures(report::Report& r);

}  // namespace mc::studies

#pragma once
/// @file
/// The full report's parts (`microcobot report`): each module's figures, computed by the studies
/// that produce them, in the architecture's order (bottom-up). The table is explicit rather than
/// filled by static registration, which a static library would drop for any unreferenced file.

#include <functional>
#include <string>
#include <vector>

#include "microcobot/report/report.h"

namespace mc::studies {

/// A section of the full report: its name (what `report --only` takes), its place in the report
/// and what computes it.
struct ReportPart {
  std::string name;
  int order = 0;
  std::function<void(report::Report&)> build;
};

/// Every part of the full report, sorted by order.
std::vector<ReportPart> report_parts();

}  // namespace mc::studies

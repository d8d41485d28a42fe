#include "microcobot/studies/report_parts.h"

#include <algorithm>

#include "microcobot/studies/control_figures.h"
#include "microcobot/studies/core_figures.h"
#include "microcobot/studies/dsp_figures.h"
#include "microcobot/studies/experiment_figures.h"
#include "microcobot/studies/haptics_figures.h"
#include "microcobot/studies/identification_figures.h"
#include "microcobot/studies/positioner_figures.h"
#include "microcobot/studies/tweezers_figures.h"

namespace mc::studies {

std::vector<ReportPart> report_parts() {
  std::vector<ReportPart> parts = {
      {"rng", 5, &rng_figures},
      {"dsp", 20, &dsp_figures},
      {"stickslip", 30, &stickslip_figures},
      {"identify", 35, &identification_figures},
      {"haptics", 40, &haptics_figures},
      {"control", 50, &control_figures},
      {"positioner", 60, &positioner_figures},
      {"tweezers", 70, &tweezers_figures},
  };
  std::stable_sort(parts.begin(), parts.end(),
                   [](const ReportPart& a, const ReportPart& b) { return a.order < b.order; });
  return parts;
}

}  // namespace mc::studies

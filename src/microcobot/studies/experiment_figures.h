#pragma once
/// @file
/// The figures of the stick-slip actuator's experiments (thesis ch. 2, Fig. 2.10-2.17): each
/// experiment of experiments.h run and drawn into a report section, with its JSON summary.

#include <string>

#include <nlohmann/json.hpp>

#include "microcobot/report/report.h"
#include "microcobot/stickslip/actuator.h"

namespace mc::studies {

/// Runs the experiment `name` (experiment_names()) on `p`, adds its section to `r` and returns its
/// summary. Throws mc::UsageError naming the known experiments when `name` is none of them.
nlohmann::json experiment_figures(const std::string& name, const stickslip::StickSlipParams& p,
                                  report::Report& r);

/// The stick-slip part of the full report: every experiment on the default axis.
void stickslip_figures(report::Report& r);

}  // namespace mc::studies

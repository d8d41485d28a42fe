#pragma once
/// @file
/// The signal toolkit's part of the full report.

#include "microcobot/report/report.h"

namespace mc::studies {

/// The LR4 crossovers of the dual-stage interface (thesis Fig. 3.8) and their all-pass sum, the
/// Welch PSD of a PRBS and one period of an MLS.
void dsp_figures(report::Report& r);

}  // namespace mc::studies

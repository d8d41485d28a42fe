#pragma once
/// @file
/// The foundations' part of the full report: the random number generator every simulation draws
/// its noise from, checked against the density it promises.

#include "microcobot/report/report.h"

namespace mc::studies {

/// A histogram of 200 000 normal draws of mc::Rng (seed 1) against the standard normal density,
/// with the draws' mean and variance.
void rng_figures(report::Report& r);

}  // namespace mc::studies

#pragma once
/// @file
/// The figures of a stick-slip axis' identification (thesis 2.5.2): one report section per step
/// of `identify all` (PE modes, asperity modes, PI hysteresis, break-away strain) with its fit
/// plots, and the full report's part, a synthetic campaign identified end to end.

#include "microcobot/report/report.h"
#include "microcobot/stickslip/ident_breakaway.h"
#include "microcobot/stickslip/ident_friction_modes.h"
#include "microcobot/stickslip/ident_hysteresis.h"
#include "microcobot/stickslip/ident_pe_modes.h"
#include "microcobot/stickslip/ident_record.h"

namespace mc::studies {

/// The PE's modes (Fig. 2.10): the free response's PSD and the step response, measured and fitted.
void pe_section(report::Report& rep, const stickslip::MeasuredRecord& rec, const stickslip::PeModesResult& r);
/// The asperity modes (Fig. 2.11): the actuator's free-response PSD and its scanning-mode step.
void friction_section(report::Report& rep, const stickslip::MeasuredRecord& rec,
                      const stickslip::FrictionModesResult& r);
/// The PI hysteresis (Fig. 2.12): the loop measured and modelled, the model and its inverse.
void hysteresis_section(report::Report& rep, const stickslip::MeasuredRecord& rec,
                        const stickslip::HysteresisResult& r);
/// The break-away strain (Fig. 2.13): the identified table and simulated against measured velocity.
void breakaway_section(report::Report& rep, const stickslip::BreakawayResult& r);

/// The identification part of the full report: a small synthetic campaign of the default axis
/// (written to a temporary directory, removed after) identified by stickslip::identify_all.
void identification_figures(report::Report& rep);

}  // namespace mc::studies

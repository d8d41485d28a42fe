#include "microcobot/stickslip/ident_all.h"

#include <fmt/format.h>

#include "microcobot/core/error.h"

namespace mc::stickslip {

StickSlipParams combine_identified(const StickSlipParams& base, const PeModesResult* pe,
                                   const FrictionModesResult& friction, const HysteresisResult& hysteresis) {
  StickSlipParams p = base;
  if (pe) p.pe = pe->params;
  p.pe.static_gain_m_V = hysteresis.static_gain_m_V;
  p.hysteresis = hysteresis.pi;
  p.friction = friction.params;
  p.validate();
  return p;
}

IdentificationRecords read_identification_records(const std::filesystem::path& dir) {
  if (!std::filesystem::is_directory(dir)) throw InvalidInput(dir.string(), 0, "not a directory");
  auto need = [&](const char* name) {
    const auto f = dir / name;
    if (!std::filesystem::exists(f)) {
      throw InvalidInput(
          f.string(), 0,
          fmt::format("missing: identify all needs {} (see docs/concepts/stick-slip.md)", name));
    }
    return f;
  };
  IdentificationRecords r;
  r.step = read_record(need("step.csv"));
  r.sine = read_record(need("sine.csv"));
  r.sawtooth = read_sawtooth_runs(dir);
  if (std::filesystem::exists(dir / "pe_step.csv")) r.pe_step = read_record(dir / "pe_step.csv");
  return r;
}

IdentifyAllResult identify_all(const std::filesystem::path& dir, const StickSlipParams& base,
                               const IdentifyAllOptions& options, const IdentifyProgress& progress) {
  return identify_all(read_identification_records(dir), base, options, progress);
}

IdentifyAllResult identify_all(const IdentificationRecords& records, const StickSlipParams& base,
                               const IdentifyAllOptions& options, const IdentifyProgress& progress) {
  if (records.sawtooth.empty()) throw InvalidInput("sawtooth: no run (step 3 needs at least one)");
  auto report = [&](const std::string& task, std::size_t done, std::size_t total) {
    if (progress) progress(task, done, total);
  };
  IdentifyAllResult out;
  const MeasuredRecord& step = records.step;
  const MeasuredRecord& sine = records.sine;
  const std::vector<SawtoothRun>& runs = records.sawtooth;
  const std::optional<MeasuredRecord>& pe_rec = records.pe_step;

  report("identify step 1 (modes)", 0, 2);
  if (pe_rec) {
    out.pe = identify_pe_modes(*pe_rec, base.pe);
  } else {
    out.notes.push_back("no pe_step record: PE modes and gain split kept from the base parameters");
  }
  report("identify step 1 (modes)", 1, 2);
  StickSlipParams with_pe = base;
  if (out.pe) with_pe.pe = out.pe->params;
  out.friction = identify_friction_modes(step, with_pe);
  report("identify step 1 (modes)", 2, 2);
  report("identify step 2 (hysteresis)", 0, 1);
  // The slider's lag at the sine frequency, from step 1, is not hysteresis.
  StickSlipParams dyn = base;
  if (out.pe) dyn.pe = out.pe->params;
  dyn.friction = out.friction.params;
  out.hysteresis = identify_hysteresis(sine, options.operators, &dyn);
  report("identify step 2 (hysteresis)", 1, 1);
  StickSlipParams p = combine_identified(base, out.pe ? &*out.pe : nullptr, out.friction, out.hysteresis);
  const ActuatorModel model(p);
  out.breakaway = identify_breakaway(runs, model, options.breakaway, [&](std::size_t d, std::size_t t) {
    report("identify step 3 (break-away, runs)", d, t);
  });
  p.breakaway = out.breakaway.table;
  p.validate();
  out.params = p;
  for (const auto& r : out.breakaway.runs) {
    if (!r.ok) out.notes.push_back("skipped run " + r.name + ": " + r.skipped);
  }
  for (const auto& c : out.breakaway.filled)
    out.notes.push_back("z_ba cell without a fitted run, interpolated: " + c);
  for (const auto& c : out.breakaway.extrapolated)
    out.notes.push_back("z_ba cell without a fitted run, extrapolated: " + c);
  return out;
}

}  // namespace mc::stickslip

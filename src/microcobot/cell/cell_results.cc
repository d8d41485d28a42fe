// A cycle's result and a batch's summary (cell_run.h): their JSON (the CLI's, the Python module's,
// the Dask campaigns' round trip) and the batch's statistics.
#include <algorithm>
#include <cmath>
#include <limits>

#include "microcobot/cell/cell_run.h"
#include "microcobot/core/error.h"

namespace mc::cell {

namespace {

nlohmann::json step_times_json(const std::array<double, AssemblyTask::kStepCount - 1>& step_s) {
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t i = 0; i < step_s.size(); ++i)
    j[std::string(AssemblyTask::name(static_cast<AssemblyTask::Step>(i)))] = step_s[i];
  return j;
}

}  // namespace

nlohmann::json CycleResult::to_json() const {
  return {{"index", index},
          {"mode", mode},
          {"master", master},
          {"success", success},
          {"verdict", verdict},
          {"cycle_s", cycle_s},
          {"placement_error_m", placement_error_m},
          {"peak_grip_N", peak_grip_N},
          {"mean_grip_N", mean_grip_N},
          {"peak_contact_N", peak_contact_N},
          {"grip_violations", grip_violations},
          {"contact_violations", contact_violations},
          {"neighbour_contacts", neighbour_contacts},
          {"clutches", clutches},
          {"search_tries", search_tries},
          {"submovements", submovements},
          {"confirmations", confirmations},
          {"handovers", handovers},
          {"path_m", path_m},
          {"side_m", side_m},
          {"clearance_m", clearance_m},
          {"part", part},
          {"release", release},
          {"wall_s", wall_s},
          {"ended_holding", ended_holding},
          {"looks", looks},
          {"looks_found", looks_found},
          {"look_error_m", look_error_m},
          {"look_wall_s", look_wall_s},
          {"seat_levelled", seat_levelled},
          {"seat_tilt_before_rad", seat_tilt_before_rad},
          {"seat_tilt_after_rad", seat_tilt_after_rad},
          {"level_rounds", level_rounds},
          {"level_s", level_s},
          {"tips_levelled", tips_levelled},
          {"tip_misalignment_before_m", tip_misalignment_before_m},
          {"tip_misalignment_after_m", tip_misalignment_after_m},
          {"level_tips_s", level_tips_s},
          {"step_s", step_times_json(step_s)}};
}

CycleResult CycleResult::from_json(const nlohmann::json& j) {
  if (!j.is_object())
    throw InvalidInput("cycle result: expected an object (got " + std::string(j.type_name()) + ")");
  CycleResult r;
  // Every key to_json() writes, with its type: a result from elsewhere is read whole or refused.
  const auto get = [&j](const char* key, auto& field) {
    const auto it = j.find(key);
    if (it == j.end()) throw InvalidInput(std::string("cycle result: missing '") + key + "'");
    try {
      it->get_to(field);
    } catch (const nlohmann::json::exception&) {
      throw InvalidInput(std::string("cycle result: '") + key + "' has the wrong type (" + it->type_name() +
                         ")");
    }
  };
  get("index", r.index);
  get("mode", r.mode);
  get("master", r.master);
  get("success", r.success);
  get("verdict", r.verdict);
  get("cycle_s", r.cycle_s);
  get("placement_error_m", r.placement_error_m);
  get("peak_grip_N", r.peak_grip_N);
  get("mean_grip_N", r.mean_grip_N);
  get("peak_contact_N", r.peak_contact_N);
  get("grip_violations", r.grip_violations);
  get("contact_violations", r.contact_violations);
  get("clutches", r.clutches);
  get("search_tries", r.search_tries);
  get("neighbour_contacts", r.neighbour_contacts);
  get("part", r.part);
  get("release", r.release);
  get("submovements", r.submovements);
  get("confirmations", r.confirmations);
  get("handovers", r.handovers);
  get("path_m", r.path_m);
  get("side_m", r.side_m);
  get("clearance_m", r.clearance_m);
  get("wall_s", r.wall_s);
  get("ended_holding", r.ended_holding);
  get("looks", r.looks);
  get("looks_found", r.looks_found);
  get("look_error_m", r.look_error_m);
  get("look_wall_s", r.look_wall_s);
  get("seat_levelled", r.seat_levelled);
  get("seat_tilt_before_rad", r.seat_tilt_before_rad);
  get("seat_tilt_after_rad", r.seat_tilt_after_rad);
  get("level_rounds", r.level_rounds);
  get("level_s", r.level_s);
  get("tips_levelled", r.tips_levelled);
  get("tip_misalignment_before_m", r.tip_misalignment_before_m);
  get("tip_misalignment_after_m", r.tip_misalignment_after_m);
  get("level_tips_s", r.level_tips_s);
  nlohmann::json steps;
  get("step_s", steps);
  for (std::size_t i = 0; i < r.step_s.size(); ++i) {
    const std::string key(AssemblyTask::name(static_cast<AssemblyTask::Step>(i)));
    const auto it = steps.find(key);
    if (it == steps.end() || !it->is_number())
      throw InvalidInput("cycle result: 'step_s' has no number for '" + key + "'");
    r.step_s[i] = it->get<double>();
  }
  return r;
}

nlohmann::json BatchSummary::to_json() const {
  return {{"mode", mode},
          {"cycles", cycles},
          {"successes", successes},
          {"success_rate", success_rate},
          {"success_rate_95ci", {success_low, success_high}},
          {"cycle_median_s", cycle_median_s},
          {"cycle_iqr_s", {cycle_q1_s, cycle_q3_s}},
          {"placement_median_m", placement_median_m},
          {"peak_grip_max_N", peak_grip_max_N},
          {"peak_contact_max_N", peak_contact_max_N},
          {"force_violations", force_violations},
          {"neighbour_contacts", neighbour_contacts},
          {"simulated_s", simulated_s},
          {"wall_s", wall_s},
          {"looks", looks},
          {"looks_found", looks_found},
          {"look_error_max_m", look_error_max_m},
          {"look_wall_s", look_wall_s}};
}

namespace {

// The q-quantile of sorted values, linearly interpolated (type 7, numpy's default).
double quantile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return std::numeric_limits<double>::quiet_NaN();
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (pos - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

}  // namespace

BatchSummary summarize(const std::vector<CycleResult>& cycles) {
  BatchSummary s;
  s.cycles = static_cast<int>(cycles.size());
  if (cycles.empty()) return s;
  s.mode = cycles.front().mode;
  std::vector<double> times, placement;
  for (const CycleResult& c : cycles) {
    s.successes += c.success ? 1 : 0;
    times.push_back(c.cycle_s);
    placement.push_back(c.placement_error_m);
    s.peak_grip_max_N = std::max(s.peak_grip_max_N, c.peak_grip_N);
    s.peak_contact_max_N = std::max(s.peak_contact_max_N, c.peak_contact_N);
    s.force_violations += c.grip_violations + c.contact_violations;
    s.neighbour_contacts += c.neighbour_contacts;
    s.simulated_s += c.cycle_s;
    s.wall_s += c.wall_s;
    s.looks += c.looks;
    s.looks_found += c.looks_found;
    s.look_error_max_m = std::max(s.look_error_max_m, c.look_error_m);
    s.look_wall_s += c.look_wall_s;
  }
  std::sort(times.begin(), times.end());
  std::sort(placement.begin(), placement.end());
  s.cycle_median_s = quantile(times, 0.5);
  s.cycle_q1_s = quantile(times, 0.25);
  s.cycle_q3_s = quantile(times, 0.75);
  s.placement_median_m = quantile(placement, 0.5);
  // Wilson's score interval at 95 % (z = 1.96): sound at 0 and at n successes, unlike Wald's.
  const double n = s.cycles, p = s.successes / n, z = 1.959964;
  s.success_rate = p;
  const double centre = (p + z * z / (2 * n)) / (1 + z * z / n);
  const double half = z * std::sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n);
  s.success_low = std::max(0.0, centre - half);
  s.success_high = std::min(1.0, centre + half);
  return s;
}

}  // namespace mc::cell

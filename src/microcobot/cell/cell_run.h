#pragma once
/// @file
/// A batch of the assembly cell run headless: each part of an
/// AssemblyBatch picked from its slot and inserted into its bore on a fresh simulated platform,
/// by the robot (mode "auto": AssemblyTask through the console input, the platform's limits in
/// force) or by the scripted watchmaker (mode "manual": cell::PickPlaceOperator on the haptic
/// master and the TéléTweez, who sees the pin through the microscope to within 1 um and has none
/// of a person's reaction time or tremor yet). Each cycle is measured from the platform's own
/// sensors and the simulation's truth: time, success (the pin down in its bore, released),
/// placement error, grip and contact forces and the ticks over their limits, path length, clutch
/// presses, the search's tries. An automatic cycle ends with every axis holding
/// (Platform::hold()).

#include <array>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "microcobot/cell/assembly_batch.h"
#include "microcobot/cell/assembly_task.h"
#include "microcobot/cell/cell_camera.h"
#include "microcobot/cell/person_operator.h"
#include "microcobot/cell/pick_place_operator.h"
#include "microcobot/cell/seat_levelling.h"
#include "microcobot/cell/tip_levelling_step.h"
#include "microcobot/core/rng.h"
#include "microcobot/platform/platform.h"
#include "microcobot/platform/platform_config.h"

namespace mc::cell {

struct CellRunParams {
  // Not an aggregate: GCC 12 at -O3 warns falsely of uninitialised strings in a CellRunParams{}
  // temporary built member by member.
  CellRunParams() = default;
  std::string mode = "auto";   ///< cell_modes()
  double max_cycle_s = 120.0;  ///< simulated; a cycle not finished by then fails
  AssemblyTaskParams task;
  /// The simulated person of the manual and assisted modes (their master: person.master).
  PersonOperatorParams person;
  /// The person's seed: part i gets person_seed * 1000003 + i, the same in every mode.
  int person_seed = 1;
  /// Headless, a step whose autonomy is `confirm` is confirmed by the supervisor this long after
  /// it started waiting (a stand-in for the operator's glance and click where no simulated
  /// person takes the step, person_model.h): its cost shows in the cycle time.
  double confirm_delay_s = 1.0;
  /// Each step's autonomy (a task file's `steps`, task_file.h; not a --params key). Headless, a
  /// `manual` step is taken over by the simulated person with the console (person.master:
  /// console), who hands back once it is done; an `assisted` step is refused (serve --cell runs it
  /// with a person).
  std::array<AssemblyTask::Autonomy, AssemblyTask::kStepCount> autonomy = all_auto();
  /// The cell's camera (mode auto): its looks at the pin in its slot, in the fingers, placed.
  CellCameraParams camera;
  /// The seat levelled by touch before each insertion (mode auto; seat_levelling.h): by default
  /// when the part rides on a parallel positioner (`positioner: parallel`).
  SeatLevellingParams level_seat;
  /// The PiezoGripper's tips levelled by touch at each cycle's start (mode auto;
  /// tip_levelling_step.h): off by default.
  TipLevellingStepParams level_tips;
  /// The scripted watchmaker (mode "scripted"), with time for the batch's longer transports (up to ~5 mm at
  /// 100 um/s, where the main scenario's is 2 mm).
  cell::PickPlaceOperatorParams manual = manual_defaults();

  template <class V>
  void visit(V& v) {
    v("mode", mode);
    v("max_cycle_s", max_cycle_s);
    v("task", task);
    v("person", person);
    v("person_seed", person_seed);
    v("confirm_delay_s", confirm_delay_s);
    v("manual", manual);
    v("camera", camera);
    v("level_seat", level_seat);
    v("level_tips", level_tips);
  }
  void validate() const;
  static std::array<AssemblyTask::Autonomy, AssemblyTask::kStepCount> all_auto() {
    std::array<AssemblyTask::Autonomy, AssemblyTask::kStepCount> a{};
    a.fill(AssemblyTask::Autonomy::kAuto);
    return a;
  }
  static cell::PickPlaceOperatorParams manual_defaults() {
    cell::PickPlaceOperatorParams m;
    m.phase_timeout_s = 90.0;
    return m;
  }
};

/// The modes, for --help and errors: "auto" (the robot: AssemblyTask), "manual" (the simulated
/// person alone), "assisted" (the same person with shared control), "scripted" (the main
/// scenario's scripted watchmaker: none of a person's limits, a reference).
std::vector<std::string> cell_modes();

struct CycleResult {
  int index = 0;
  std::string mode;
  std::string master;  ///< the person's master ("" for auto and scripted)
  bool success = false;
  std::string verdict;   ///< one line
  double cycle_s = 0.0;  ///< simulated time to the end of the task (or the limit)
  double placement_error_m = 0.0;
  double peak_grip_N = 0.0, mean_grip_N = 0.0;  ///< mean over the ticks the pin was gripped
  double peak_contact_N = 0.0;
  int grip_violations = 0, contact_violations = 0;  ///< ticks over the platform's limits
  /// The gripper's steps striking another part of the scene (layout grid; microworld/neighbours.h).
  int neighbour_contacts = 0;
  int clutches = 0;
  int search_tries = 0;   ///< the task's search points, or the times the person's pin met the rim
  int submovements = 0;   ///< the person's aimed movements
  int confirmations = 0;  ///< steps the supervisor confirmed (autonomy `confirm`)
  int handovers = 0;      ///< manual steps the simulated person took over and handed back (auto)
  double path_m = 0.0;    ///< length of the measured tip's path
  double side_m = 0.0, clearance_m = 0.0;
  std::string part = "pin";        ///< "pin" (into a bore) or "flat" (onto a flat seat)
  std::string release;             ///< the release strategy the part was given (microworld/release.h)
  double wall_s = 0.0;             ///< the cycle's wall-clock time, the platform's construction included
  int looks = 0, looks_found = 0;  ///< the cell camera's looks (CellCameraParams::enabled)
  double look_error_m = 0.0;       ///< the largest |seen - true| of the pin's centre in x-y, found looks
  double look_wall_s = 0.0;        ///< wall-clock time spent rendering and measuring
  bool ended_holding =
      false;  ///< every axis' target (the rotary's too) at its measured position, the coupling off
  /// The seat levelled before the insertion (seat_levelling.h): whether it ran, the tilt its first
  /// and last rounds of touches measured, its rounds and its simulated time (within the insert step's).
  bool seat_levelled = false;
  double seat_tilt_before_rad = 0.0, seat_tilt_after_rad = 0.0;
  int level_rounds = 0;
  double level_s = 0.0;
  /// The tips levelled at the cycle's start (tip_levelling_step.h): whether they were, their
  /// misalignment before and after (the simulation's truth), its simulated time.
  bool tips_levelled = false;
  double tip_misalignment_before_m = 0.0, tip_misalignment_after_m = 0.0;
  double level_tips_s = 0.0;
  /// Simulated seconds spent in each step of the task (auto) or of the person (manual, assisted),
  /// indexed by AssemblyTask::Step (kDone: none); all zero for the scripted watchmaker, whose
  /// phases differ. Where a cycle's time goes, mode against mode.
  std::array<double, AssemblyTask::kStepCount - 1> step_s{};
  nlohmann::json to_json() const;
  /// Back from to_json()'s object (results gathered from other processes, e.g. the Python
  /// module's Dask campaigns, then summarized). Throws mc::InvalidInput naming a missing or
  /// mistyped key.
  static CycleResult from_json(const nlohmann::json& j);
};

/// Median, quartiles and the success rate with its 95 % Wilson interval.
struct BatchSummary {
  std::string mode;
  int cycles = 0, successes = 0;
  double success_rate = 0.0, success_low = 0.0, success_high = 0.0;
  double cycle_median_s = 0.0, cycle_q1_s = 0.0, cycle_q3_s = 0.0;
  double placement_median_m = 0.0;
  double peak_grip_max_N = 0.0, peak_contact_max_N = 0.0;
  int force_violations = 0;
  int neighbour_contacts = 0;  ///< the gripper's steps striking a neighbour, every cycle
  double simulated_s = 0.0, wall_s = 0.0;
  int looks = 0, looks_found = 0;  ///< the cell camera's, over the batch
  double look_error_max_m = 0.0;   ///< the largest of the cycles' look_error_m
  double look_wall_s = 0.0;
  nlohmann::json to_json() const;
};

/// One part's cycle on its own simulated platform, steppable: the operator's controls (pause,
/// take over, ...) reach its task between steps (tests, the console).
class CellCycle {
 public:
  /// `base` is the platform's configuration (its world is replaced by the job's). Throws
  /// mc::Error (parameters, a platform that cannot be built).
  CellCycle(const AssemblyJob& job, const CellRunParams& params, platform::PlatformConfig base);
  ~CellCycle();
  CellCycle(const CellCycle&) = delete;
  CellCycle& operator=(const CellCycle&) = delete;

  /// Runs for `duration_s` of simulated time, or to the end of the cycle (then 0.2 s more, the
  /// stage seen holding where it was left).
  void run_for(double duration_s);
  /// To the end, or to params.max_cycle_s.
  void run_to_end();
  bool finished() const noexcept { return finished_; }
  /// Called at the end of every operator tick with its time, on the loop (real-time rules):
  /// an observer, or an operator's hand on the task's controls at a given moment.
  void set_observer(std::function<void(double t_s)> observer) { observer_ = std::move(observer); }
  /// The automatic task (null in the other modes).
  AssemblyTask* task() noexcept { return task_.get(); }
  /// The simulated person (null in the other modes).
  const PersonOperator* person() const noexcept { return person_.get(); }
  platform::Platform& platform() noexcept { return *platform_; }
  CycleResult result() const;

 private:
  struct Meter;
  AssemblyJob job_;
  CellRunParams params_;
  std::chrono::steady_clock::time_point start_;
  std::unique_ptr<platform::Platform> platform_;
  std::unique_ptr<AssemblyTask> task_;
  std::unique_ptr<cell::PickPlaceOperator> manual_;
  std::unique_ptr<PersonOperator> person_;
  std::unique_ptr<Meter> meter_;
  std::function<void(double)> observer_;
  Eigen::Vector3d home_m_;
  bool finished_ = false, held_ = false, settled_ = false;
  double finished_at_s_ = 0.0;
  double waiting_s_ = 0.0;  // how long the task has awaited confirmation
  Rng vision_rng_;          // the cell's vision of the part without a camera (the verify step)
  std::unique_ptr<CellCamera> camera_;
  int looks_ = 0, looks_found_ = 0;
  double look_error_m_ = 0.0, look_wall_s_ = 0.0;
  std::string last_look_miss_;   // why the last look that found nothing did not
  bool look_requested_ = false;  // the operator stopped the run for a look
  /// The seat's levelling before the insertion: the procedure (null: none), ticked in place of the
  /// task while it runs; its plate move planned off the loop (plan_level_move()) and started on it.
  struct Levelling {
    std::unique_ptr<SeatLevelling> procedure;
    std::optional<motion::PoseTrajectory> path;
    bool plan_requested = false, path_ready = false, move_started = false;
    std::uint64_t stops = 0;                 // the platform's stopped pose moves when the move started
    double s = 0.0;                          // its simulated time
    std::unique_ptr<TipLevellingStep> tips;  // the tips' levelling at the start (null: none)
    double tips_s = 0.0;
    bool failed = false;  // either failed: the cycle ended there
  } level_;
  /// Whether the leveller drives this tick (the task at its insertion's start, the robot's).
  bool levelling_now() const noexcept;
  void level_tick(const TaskSensors& s, const runtime::TickInfo& t);
  void plan_level_move();
  /// The look the task awaits, off the loop: the frames rendered from the truth, measured, seen.
  void look();
  int confirmations_ = 0;
  /// A manual step of the task: the person takes it over, acts, and hands back once their step
  /// moved on (the task then goes on from the next step) or they gave up (the task does the step).
  void hand_over(const runtime::TickInfo& t);
  bool person_has_step_ = false;
  AssemblyTask::Step person_step_ = AssemblyTask::Step::kApproach;
  int handovers_ = 0;
};

/// One part, run to its end.
CycleResult run_cycle(const AssemblyJob& job, const CellRunParams& params, platform::PlatformConfig base);

/// Every part in order; `progress(i, result)` after each.
std::vector<CycleResult> run_batch(const std::vector<AssemblyJob>& jobs, const CellRunParams& params,
                                   const platform::PlatformConfig& base,
                                   const std::function<void(const CycleResult&)>& progress = {});

BatchSummary summarize(const std::vector<CycleResult>& cycles);

}  // namespace mc::cell

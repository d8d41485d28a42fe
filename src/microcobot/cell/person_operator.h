#pragma once
/// @file
/// A simulated person doing one insertion of the assembly cell through the platform's own
/// inputs, manually or with shared control (teleop/virtual_fixtures.h):
///
///   master "haptic"   the dual-stage haptic handle (x, y; the slave follows at the motion
///                     scale, clutching near the workspace's edge), the Z thumb wheel and the
///                     TéléTweez, whose finger force tells the grip;
///   master "console"  the console's joystick (a rate control: stage velocity in x, y, z) and
///                     its gripper slider, the grip force read off the console's display;
///   master "click"    the console's click-to-go (docs/console.md): a move in the plane is a click
///                     on the microscope's image, the mouse cursor aimed at the target on the
///                     screen in Fitts sub-movements (the display's scale: screen_px_per_m, zoomed
///                     so that a target is at least min_click_px wide); the click sends the stage
///                     straight there at stage_pace_m_s under its own closed loop, and the person
///                     watches it arrive before judging again (a corrective click, or done). Z by
///                     the joystick, the gripper slider, the dial: as "console". Manual only: the
///                     click is the platform's move already, and shared control guides a rate.
///
/// The person looks through the microscope (the true positions, made out within vision_sd_m),
/// moves in minimum-jerk sub-movements timed by Fitts' law with the endpoint noise, reaction
/// time and tremor of person_model.h, and goes through the steps of the automatic task
/// (assembly_task.h) so that the modes compare step by step: approach over the pin, descend,
/// grasp, lift, transport the pin over its bore, insert (down; a contact felt above the bore's
/// depth means the pin sits on the rim: up a little, look again, re-aim, down again), release,
/// retract. A flat part (AssemblyGoal::flat_seat) is grasped at half its thickness, set down until
/// its seat is felt, and let go by its process sheet's strategy (open; shake: the console's Shake
/// held; roll: the dial turned with the plate on its seat). Orientation (the rotary axis under the gripper):
/// the person turns the console's dial (the rotor follows its angle) to square the open fingers with the pin
/// on the tray (align) and the carried pin with its bore (rotate), judging the edges' directions by eye
/// (yaw_vision_sd_rad), in aimed sub-movements of the dial like any other; a pin on the rim makes them look
/// at its orientation again too.
///
/// Assisted (shared control): the cell's vision gives the pin's position and, once it is held,
/// its offset from the finger tips (within assist_vision_sd_m, measured once per step); the platform
/// then guides the slave to the pin, and the carried pin to its bore's axis, with the insertion
/// funnel round the rim and the coarse-far/fine-near scaling (teleop/virtual_fixtures.h). The
/// person trusts the guidance: they aim within the fixture's capture radius, not at the last
/// micrometre; the step's working height is a stop the person rolls into (grasping, carrying,
/// clear of the pins); the turns are the platform's, to the orientations the cell's vision
/// measures (within assist_yaw_sd_rad), the person holding the deadman. Everything else (the
/// person, the seeds, the parts) is the manual run's.
///
/// act() runs as the platform's operator task: real-time safe (no allocation, lock, exception,
/// I/O). The person lets go of everything when done or when a step times out (gave up).

#include <array>
#include <limits>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include "microcobot/cell/assembly_task.h"
#include "microcobot/cell/person_model.h"
#include "microcobot/platform/platform.h"

namespace mc::cell {

struct PersonOperatorParams {
  std::string master = "haptic";  ///< "haptic", "console" or "click" (header)
  PersonParams person;
  double pin_tolerance_m = 10e-6;  ///< over the pin before descending
  double bore_tolerance_m = 2e-6;  ///< manual: the pin over its bore before inserting
  /// What the cell's camera makes out of the pin and the tips (SD), at 5x (1.1 um pixels):
  /// docs/benchmarks.md's worst tracking rms on the validation sets, a part's corner 0.033 px and
  /// the tool's tips 0.026 px, with the calibration's worst residual 0.052 px: 0.067 px = 0.074 um,
  /// rounded up.
  double assist_vision_sd_m = 0.1e-6;
  double assisted_tolerance_m = 15e-6;  ///< assisted: the target width planned for (in the capture)
  /// Assisted: the slave speed the person plans moves in the plane for. The platform paces the
  /// target to the stage's (teleop::VirtualFixtureParams::max_speed_m_s, 0.5 mm/s), so the
  /// person no longer has to: twice that turns a minimum-jerk move (peak 1.875x its mean speed)
  /// into the stage's pace most of the way; the console's joystick allows 1 mm/s.
  double assisted_pace_m_s = 1.0e-3;
  double z_tolerance_m = 10e-6;  ///< heights judged by eye (the depth of field)
  /// Orientations judged by eye: two edges' directions compared through the microscope (SD), and
  /// the misalignment the person accepts. A square pin in its bore tolerates 1.15 deg at the
  /// least (300 um, 3 um of clearance; microworld/pick_place_world.h).
  double yaw_vision_sd_rad = 5e-3;  ///< 0.3 deg
  double yaw_tolerance_rad = 9e-3;  ///< 0.5 deg
  /// Assisted: the cell's vision of an orientation (SD): a 100 um edge located to 0.1 um at both
  /// ends (assist_vision_sd_m) gives 1.4 mrad; rounded up.
  double assist_yaw_sd_rad = 2e-3;
  double still_m = 5e-6;             ///< the tool seen still: it moved less than this ...
  double still_window_s = 0.1;       ///< ... over this (one tremor period: tremor averages out)
  double jam_margin_m = 20e-6;       ///< a contact this far above the bore's depth: on the rim
  double jam_retreat_m = 30e-6;      ///< up by this before looking again
  double press_m = 10e-6;            ///< inserting: aimed this far below the bore's floor
  double hand_limit_m = 35e-3;       ///< haptic: clutch before the hand passes this
  double pinch_m_s = 10e-3;          ///< TéléTweez lever closing speed
  double max_pinch_m = 10e-3;        ///< the levers' travel
  double felt_grip_N = 0.03;         ///< TéléTweez finger force that tells the part is held
  double slider_m_s = 600e-6;        ///< console gripper slider speed (opening units)
  double grip_seen_N = 0.25e-3;      ///< console: a grip force read as held
  double joystick_travel_m = 15e-3;  ///< console: the joystick's half travel (tremor scale)
  /// click: the microscope's image on the screen, px per metre of the stage: the 5x camera's 1.41 mm
  /// field on a 640 px panel (docs/console.md's layout).
  double screen_px_per_m = 4.5e5;
  /// click: the narrowest target the person clicks at; a finer one is clicked zoomed in (a higher
  /// objective) so that it is this wide on the screen.
  double min_click_px = 4.0;
  /// A flat part's release (its process sheet's strategy, microworld/release.h): the console's
  /// Shake held this long (a press, seen to take, let go: two reaction times' worth), or the dial
  /// turned by the task's roll_rad with the plate on its seat. The haptic master has no burst: its
  /// person rolls instead.
  double shake_hold_s = 0.4;
  /// Inserting: the pin seen no lower for this long, well into its bore (half its depth): it is
  /// at the bottom, felt or not. The hand may arrive at its aimed height (within z_tolerance_m)
  /// with the pin a micrometre short of the floor, no contact to feel (seed 4111, part 9).
  double stalled_s = 1.0;
  double step_timeout_s = 60.0;  ///< a step not done by then: the person gives up
  int max_jams = 12;             ///< rim contacts before the person gives up

  template <class V>
  void visit(V& v) {
    v("master", master);
    v("person", person);
    v("pin_tolerance_m", pin_tolerance_m);
    v("bore_tolerance_m", bore_tolerance_m);
    v("assist_vision_sd_m", assist_vision_sd_m);
    v("assisted_tolerance_m", assisted_tolerance_m);
    v("assisted_pace_m_s", assisted_pace_m_s);
    v("z_tolerance_m", z_tolerance_m);
    v("yaw_vision_sd_rad", yaw_vision_sd_rad);
    v("yaw_tolerance_rad", yaw_tolerance_rad);
    v("assist_yaw_sd_rad", assist_yaw_sd_rad);
    v("still_m", still_m);
    v("still_window_s", still_window_s);
    v("jam_margin_m", jam_margin_m);
    v("jam_retreat_m", jam_retreat_m);
    v("press_m", press_m);
    v("hand_limit_m", hand_limit_m);
    v("pinch_m_s", pinch_m_s);
    v("max_pinch_m", max_pinch_m);
    v("felt_grip_N", felt_grip_N);
    v("slider_m_s", slider_m_s);
    v("grip_seen_N", grip_seen_N);
    v("joystick_travel_m", joystick_travel_m);
    v("screen_px_per_m", screen_px_per_m);
    v("min_click_px", min_click_px);
    v("shake_hold_s", shake_hold_s);
    v("stalled_s", stalled_s);
    v("step_timeout_s", step_timeout_s);
    v("max_jams", max_jams);
  }
  /// Throws mc::InvalidParams naming the field.
  void validate() const;
};

class PersonOperator {
 public:
  using Step = AssemblyTask::Step;
  /// `task` gives the geometry (heights, speeds' limits); `goal` what the cell knows of the part.
  /// Throws mc::InvalidParams.
  PersonOperator(platform::Platform& platform, const PersonOperatorParams& params,
                 const AssemblyTaskParams& task, const AssemblyGoal& goal, bool assisted, std::uint64_t seed);

  /// One operator tick (the platform's operator task). Real-time safe.
  void act(const runtime::TickInfo& tick) noexcept;
  /// The person takes the automatic task's step `s` over at `t_s` (a manual step of a headless
  /// run): their hands where the platform is (the joystick at rest, the
  /// gripper slider at the opening the coupling commands, the dial at the rotor's target), what
  /// they know of the pin from how it is held, and the step begun. Master console only: the
  /// TéléTweez' levers would command the held pin's grip from their own opening.
  void take_over(Step s, double t_s) noexcept;
  /// Hands back: lets go of every input (the deadman too), so that the task drives again.
  void hand_back() noexcept { let_go(); }

  Step step() const noexcept { return step_; }
  bool done() const noexcept { return step_ == Step::kDone; }
  bool gave_up() const noexcept { return gave_up_; }
  std::string_view give_up_reason() const noexcept { return reason_; }
  int clutches() const noexcept { return clutches_; }
  int jams() const noexcept { return jams_; }
  int submovements() const noexcept {
    return xy_.submovements() + z_.submovements() + yaw_.submovements() + cursor_.submovements();
  }

 private:
  void enter(Step s, double t) noexcept;
  void give_up(const char* why) noexcept;
  void let_go() noexcept;
  /// Steers the tip (or the carried pin) by the seen error in the plane, planning for a target
  /// `width_m` wide; true once seen within `tolerance_m`.
  bool steer(const Eigen::Vector2d& error_m, double tolerance_m, double t, double width_m) noexcept;
  /// steer() with the console's click-to-go (master click).
  bool click_steer(const Eigen::Vector2d& error_m, double tolerance_m, double t) noexcept;
  /// What the person aims at: the tolerance alone, or with shared control the guidance's
  /// capture (assisted_tolerance_m), which pulls the slave the rest of the way.
  double aim_width(double tolerance_m) const noexcept {
    return assisted_ ? std::max(tolerance_m, p_.assisted_tolerance_m) : tolerance_m;
  }
  /// Brings the tip to height `z_goal`, planning for a target `width_m` wide (0: the tolerance);
  /// true once seen within `tolerance_m`.
  bool climb(double z_goal, double tip_z, double tolerance_m, double t, double width_m = 0.0) noexcept;
  /// The width a height is aimed at: the eye's tolerance, or with shared control the height
  /// stop's capture (assisted_tolerance_m), which holds the slave at the height.
  double aim_height_width() const noexcept { return aim_width(p_.z_tolerance_m); }
  /// The working height of the current step (the assisted run's height stop).
  double step_height_z() const noexcept;
  void apply(double t) noexcept;
  /// Shared control: the fixtures for the current step (assisted runs).
  void assist() noexcept;
  /// `p` as the person sees it (or, with `sd_m`, the cell's tracker).
  Eigen::Vector2d seen(const Eigen::Vector2d& p, double sd_m = -1.0) noexcept;
  /// The tool seen still: moved less than still_m over the last still_window_s (a person waits
  /// for the stage to arrive before judging where it is).
  bool tool_still() const noexcept;
  /// Turns the fingers by what the person sees of `misalignment` (true, modulo 90 deg: the fingers
  /// against the pin on the tray when aligning, the carried pin against its bore when rotating);
  /// true once it is seen within yaw_tolerance_rad. Assisted: the platform turns by what its
  /// vision sees, true once it has arrived.
  bool turn(double misalignment, double t) noexcept;
  /// Turns the fingers by `delta_rad` on the dial as the person sees it (a flat part's roll); true
  /// once the turn is seen done within yaw_tolerance_rad.
  bool turn_by(double delta_rad, double t) noexcept;
  /// The carried pin's misalignment with its bore (true, modulo 90 deg).
  double bore_misalignment() const noexcept;

  platform::Platform& platform_;
  const devices::SimulatedDevices& sim_;
  PersonOperatorParams p_;
  AssemblyGoal goal_;
  bool assisted_;
  bool haptic_;
  bool click_;  // master click: the plane by click-to-go
  Rng rng_;
  Reach xy_, z_;  // the hand in the plane (haptic: hand metres; console: stage metres), the height
  Reach cursor_;  // click: the mouse cursor on the screen [px of the current zoom]
  Reach yaw_;     // the console's dial (x: the rotor's angle it asks for) [rad]
  Tremor tremor_;
  double base_scale_;
  double grasp_z_, safe_z_, carry_z_, inserted_z_;
  Step step_ = Step::kApproach;
  double step_t0_ = 0.0;
  bool gave_up_ = false;
  const char* reason_ = "";
  devices::OperatorHand hand_;
  teleop::ConsoleInput console_;
  bool clutching_ = false;
  int clutches_ = 0, jams_ = 0;
  double roll_rad_ = 0.0;  // a flat part's roll (the task's roll_rad)
  /// The release: 0 opening, 1 its strategy, 2 done; the strategy's start; a roll's dial angle;
  /// the console's Shake held.
  struct Release {
    int stage = 0;
    double t0_s = 0.0;
    double roll_goal_rad = 0.0;
    bool shaking = false;
  } release_;
  /// Click-to-go: the stage goes to the last click (`active`), there (its z: the height at the
  /// click), since.
  struct ClickGoal {
    bool active = false;
    Eigen::Vector3d at_m = Eigen::Vector3d::Zero();
    double since_s = 0.0;
  } click_goal_;
  double cursor_scale_ = 0.0;  // the screen's px per metre (zoom)
  /// The insertion: backing off the rim; the lowest tip height seen, and since when.
  struct Insertion {
    bool rising = false;
    double lowest_z_m = 0.0;
    double lowest_t_s = 0.0;
  } insertion_;
  double pinch_ = 0.0;        // TéléTweez lever closing [m]
  double slider_ = 0.0;       // console gripper opening [m]
  double held_since_ = -1.0;  // grip first felt (the person stops closing a reaction later)
  Eigen::Vector2d pin_offset_seen_ = Eigen::Vector2d::Zero();  // pin - tips, as vision saw it
  Eigen::Vector2d pin_seen_ = Eigen::Vector2d::Zero();         // the pin on the tray, seen
  double rim_z_ = 0.0;  // tip height at which the carried pin meets the plate
  /// Turns: assisted, the platform's turn's goal, under way, and the tolerance it ends within
  /// (the task's); rotate's turn done.
  struct Turn {
    double goal_rad = std::numeric_limits<double>::quiet_NaN();
    bool under_way = false;
    double arrived_rad = 0.0;
    bool rotated = false;
  } turn_;
  /// The finger tips' positions, one per operator tick (a ring), and the window over which the
  /// person judges the tool still.
  static constexpr int kHistory = 256;
  struct TipHistory {
    std::array<Eigen::Vector3d, kHistory> ring{};
    int count = 0, window_ticks = 1;
    const Eigen::Vector3d& back(int ago) const noexcept {
      return ring[static_cast<std::size_t>((count - 1 - ago) % kHistory)];
    }
    void push(const Eigen::Vector3d& tip) noexcept {
      ring[static_cast<std::size_t>(count % kHistory)] = tip;
      ++count;
    }
  } tips_;
  Eigen::Vector2d tool_xy_ = Eigen::Vector2d::Zero();  // the finger tips, this tick
};

}  // namespace mc::cell

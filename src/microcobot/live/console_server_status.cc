// What the console server says about the platform (docs/console.md, Channels): the JSON of the
// scene and status channels, and the recording's events of what the status shows changing.
// console_server.cc serves the clients and the channels.
#include "microcobot/live/console_server.h"

#include <cmath>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "microcobot/imaging/camera_params.h"
#include "microcobot/live/console_task.h"

namespace mc::live {

using nlohmann::json;

void ConsoleServer::note_changes(const LiveStatus& s) {
  const LiveStatus& was = last_status_;
  if (s.demo && !was.demo) note(EventLevel::kInfo, "demo", "the scripted demo operator drives");
  if (s.demo && s.demo_phase != was.demo_phase && !s.demo_phase.empty())
    note(EventLevel::kInfo, "demo_phase", s.demo_phase);
  if (!s.demo && was.demo) {
    // How it ended, in the words the console shows.
    const DemoResult& r = s.demo_result;
    std::string how = "the scripted demo ended: " + std::string(DemoResult::name(r.outcome));
    if (!r.phase.empty()) how += " (" + r.phase + ")";
    if (!r.reason.empty()) how += ": " + r.reason;
    if (std::isfinite(r.placement_error_m))
      how += fmt::format(", placement error {:.2f} um", 1e6 * r.placement_error_m);
    note(r.outcome == DemoResult::Outcome::kGaveUp || r.outcome == DemoResult::Outcome::kMissed
             ? EventLevel::kWarning
             : EventLevel::kInfo,
         "demo_end", how);
  }
  if (s.control != was.control && !s.control.empty())
    note(EventLevel::kInfo, "control", "the " + s.control + " drives the coupling");
  if (s.estopped != was.estopped)
    note(s.estopped ? EventLevel::kWarning : EventLevel::kInfo, "estopped",
         s.estopped ? "e-stop latched: every device in its safe state" : "e-stop cleared");
  if (s.last_error != was.last_error && !s.last_error.empty())
    note(EventLevel::kError, "platform_error", s.last_error);
  if (s.restarts != was.restarts) note(EventLevel::kInfo, "restart", "the platform was rebuilt");
  for (const auto& [kind, message] : task_changes(was.task, s.task))
    note(kind == "task_end" && s.task->inserted != 1 ? EventLevel::kWarning : EventLevel::kInfo, kind,
         message);
  last_status_ = s;
}

RobotBodies ConsoleServer::robot_bodies() const {
  RobotBodies b;
  b.part_side_m = live_.part_side_m();
  b.part_height_m = live_.part_height_m();
  b.finger_width_m = live_.finger_width_m();
  b.finger_length_m = live_.finger_length_m();
  return b;
}

std::string ConsoleServer::robot_scene_json(double t_s) const {
  return frames_.scene_update_json(robot_bodies(), t_s);
}

std::string ConsoleServer::scene_json() const {
  const auto& c = live_.limits();
  json j{{"kind", "pick-place"},
         {"part_side_m", live_.part_side_m()},
         {"part_height_m", live_.part_height_m()},
         {"hole_side_m", live_.hole_side_m()},
         {"hole_depth_m", live_.hole_depth_m()},
         // The orientations and the rotary axis' travel (both 0: no rotary axis).
         {"part_yaw_rad", live_.part_yaw_rad()},
         {"hole_yaw_rad", live_.hole_yaw_rad()},
         {"theta_min_rad", c.min_theta_rad},
         {"theta_max_rad", c.max_theta_rad},
         {"target_m", live_.target_m()},
         {"tolerance_m", live_.placement_tolerance_m()},
         {"max_opening_m", c.max_opening_m},
         {"finger_width_m", live_.finger_width_m()},
         {"workspace_min_m", c.min_m},
         {"workspace_max_m", c.max_m},
         {"max_speed_m_s", c.max_speed_m_s},
         // The gauges' full scales are the limits the platform enforces.
         {"force_full_scale_N", live_.contact_force_limit_N()},
         {"grip_force_limit_N", live_.grip_force_limit_N()},
         {"contact_force_limit_N", live_.contact_force_limit_N()}};
  // The objectives the microscope panel draws with, by the turret's index: the camera's, or without
  // a camera the library's table (imaging/camera_params.h). The page keeps no optics of its own.
  json turret = json::array();
  for (const imaging::ObjectiveParams& o :
       live_.has_camera() ? live_.camera_params().objectives : imaging::objective_table())
    turret.push_back({{"name", o.name},
                      {"magnification", o.magnification},
                      {"numerical_aperture", o.numerical_aperture},
                      {"wavelength_m", o.wavelength_m}});
  j["optics"] = {{"objectives", turret}};
  if (live_.has_camera()) {
    // What the microscope panel needs: the turret, the focus travel, the sensor, the settings'
    // ranges (the current state comes with each frame on /camera/state).
    const devices::CameraDeviceParams& cam = live_.camera_params();
    json objectives = json::array();
    for (const auto& o : cam.objectives)
      objectives.push_back({{"name", o.name},
                            {"magnification", o.magnification},
                            {"m_per_px", cam.sensor.pixel_pitch_m / o.magnification}});
    j["camera"] = {{"objectives", objectives},
                   {"focus_min_m", c.focus_min_m},
                   {"focus_max_m", c.focus_max_m},
                   {"focus_speed_m_s", cam.focus_speed_m_s},
                   {"width_px", cam.sensor.width_px},
                   {"height_px", cam.sensor.height_px},
                   {"frame_rate_Hz", cam.frame_rate_Hz()},
                   {"exposure_range_s", {c.min_exposure_s, c.max_exposure_s}},
                   {"gain_range", {c.min_gain, c.max_gain}},
                   {"view_center_m", {cam.view_center_x_m, cam.view_center_y_m}},
                   // How a recording keeps the camera unless its record_start says (the page's choice).
                   {"record_video", recorded_video_name(params_.record_video)}};
  } else {
    j["camera"] = nullptr;
  }
  // The scene's other parts (a grid load's: microworld/neighbours.h), where they stand.
  json others = json::array();
  const microworld::PickPlaceParams& w = live_.scene_world();
  for (int i = 0; i < w.neighbour_count; ++i) {
    const microworld::NeighbourPart& n = w.neighbours[static_cast<std::size_t>(i)];
    others.push_back({{"xy_m", {n.xy_m.x(), n.xy_m.y()}},
                      {"yaw_rad", n.yaw_rad},
                      {"side_m", n.side_m},
                      {"top_z_m", n.top_z_m}});
  }
  j["neighbours"] = std::move(others);
  const std::string no_demo = live_.demo_unavailable_reason();
  j["demo_available"] = no_demo.empty();
  j["demo_unavailable_reason"] = no_demo;
  if (live_.optical_trap_scene()) {
    // The probe bead (the telemetry's part_* channels) and the stuck bead; forces in piconewtons:
    // the gauge's full scale is the trap's escape force, k times the probe's radius.
    const auto& trap = live_.optical_trap().trap;
    j["kind"] = "optical-trap";
    j["bead_radius_m"] = trap.bead_radius_m;
    j["obstacle_m"] = live_.obstacle_m();
    j["obstacle_radius_m"] = trap.obstacle_radius_m;
    j["force_full_scale_N"] = trap.trap_stiffness_N_per_m * trap.bead_radius_m;
  }
  return j.dump();
}

std::string ConsoleServer::status_json() {
  const LiveStatus s = live_.status();
  json lifecycle = json::object();
  const char* names[6] = {"axis_x", "axis_y", "axis_z", "gripper", "haptic", "tweezers"};
  for (std::size_t i = 0; i < 6; ++i) lifecycle[names[i]] = std::string(devices::to_string(s.lifecycle[i]));
  if (s.has_rotary) lifecycle["axis_theta"] = std::string(devices::to_string(s.rotary_lifecycle));
  const std::string recording = recording_ ? recording_->name() : std::string();
  json j = {{"t_s", s.t_s},
            {"estopped", s.estopped},
            {"controlled", controller_.load() != 0},
            {"console_fresh", s.console_fresh},
            {"control", s.control},
            {"demo", s.demo},
            {"demo_phase", s.demo_phase},
            {"lifecycle", lifecycle},
            {"overruns", s.overruns},
            {"tick_p99_us", tick_p99_us_.load()},
            {"tick_cpu_p99_us", tick_cpu_p99_us_.load()},
            {"command_latency_ms",
             {{"count", latency_.count()},
              {"p50", 1e3 * latency_.quantile_s(0.5)},
              {"p99", 1e3 * latency_.quantile_s(0.99)},
              {"max", 1e3 * latency_.max_s()}}},
            {"link_cost_us",
             {{"count", link_cost_.count()},
              {"p50", 1e6 * link_cost_.quantile_s(0.5)},
              {"p99", 1e6 * link_cost_.quantile_s(0.99)},
              {"max", 1e6 * link_cost_.max_s()}}},
            {"clients", server_.client_count()},
            {"recording", recording.empty() ? json(nullptr) : json(recording)},
            {"last_error", s.last_error},
            {"ticks", s.ticks}};
  j["camera"] = s.camera ? json{{"frames", s.camera_frames},
                                {"dropped", s.camera_dropped},
                                {"focus_z_m", s.focus_z_m},
                                {"focus_target_m", s.focus_target_m},
                                {"objective", s.objective}}
                         : json(nullptr);
  j["task"] = task_status_json(s.task);
  if (s.vision) {
    // The stage positioned by vision: what the camera thread's tracker and servo see and do.
    const perception::PositionerStatus& v = *s.vision;
    j["vision"] = {{"taught", v.taught},
                   {"found", v.found},
                   {"has_goal", v.has_goal},
                   {"state", v.state},
                   {"error", v.error},
                   {"tool_px", {v.tool_u_px, v.tool_v_px}},
                   {"goal_px", v.has_goal ? json::array({v.goal_u_px, v.goal_v_px}) : json(nullptr)},
                   {"error_m", v.error_m},
                   {"in_position", v.in_position},
                   {"confidence", v.confidence},
                   {"stage_m", {v.stage_x_m, v.stage_y_m}},
                   {"m_per_px", v.m_per_px},
                   {"calibrated", v.calibrated},
                   {"frames", v.frames},
                   {"commands", v.commands}};
  } else {
    j["vision"] = nullptr;
  }
  if (s.grip_vision) {
    // The grip force measured by vision (null force: not measured in the last frame).
    const perception::VisionGripStatus& g = *s.grip_vision;
    const auto number_or_null = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    j["grip_vision"] = {{"state", g.state},
                        {"error", g.error},
                        {"tared", g.tared},
                        {"grip_force_N", number_or_null(g.grip_force_N)},
                        {"gap_m", number_or_null(g.gap_m)},
                        {"contact_force_N", number_or_null(g.contact_force_N)},
                        {"bend_m", number_or_null(g.bend_m)},
                        {"free_opening_m", g.free_opening_m},
                        {"confidence", g.confidence},
                        {"frames", g.frames},
                        {"tares", g.tares}};
  } else {
    j["grip_vision"] = nullptr;
  }
  if (s.levelling) {
    // The tips' levelling (Level tips): its state, why it failed, the misalignment (null: the
    // gripper does not know it, a driver's).
    const platform::TipLevellingStatus& l = *s.levelling;
    const auto metres_or_null = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    j["levelling"] = {{"state", platform::to_string(l.state)},
                      {"phase", microworld::to_string(l.phase)},
                      {"failure", l.failure},
                      {"passes", l.passes},
                      {"misalignment_before_m", metres_or_null(l.misalignment_before_m)},
                      {"misalignment_m", metres_or_null(l.misalignment_m)},
                      {"peak_contact_N", l.peak_contact_N}};
  } else {
    j["levelling"] = nullptr;
  }
  const DemoResult& d = s.demo_result;
  if (d.outcome == DemoResult::Outcome::kNone) {
    j["demo_result"] = nullptr;
  } else {
    j["demo_result"] = {
        {"outcome", DemoResult::name(d.outcome)},
        {"phase", d.phase},
        {"placement_error_m", std::isfinite(d.placement_error_m) ? json(d.placement_error_m) : json(nullptr)},
        {"reason", d.reason},
        {"duration_s", d.duration_s}};
  }
  return j.dump();
}

}  // namespace mc::live

#include "microcobot/live/robot_frames.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <nlohmann/json.hpp>

namespace mc::live {
namespace {

using nlohmann::json;

double finite(double v) { return std::isfinite(v) ? v : 0.0; }

json stamp(double t_s) {
  const double t = std::isfinite(t_s) && t_s > 0.0 ? t_s : 0.0;
  const double sec = std::floor(t);
  auto nsec = static_cast<std::int64_t>(std::llround((t - sec) * 1e9));
  auto whole = static_cast<std::int64_t>(sec);
  if (nsec >= 1000000000) {  // rounding carried into the next second
    nsec -= 1000000000;
    ++whole;
  }
  return {{"sec", whole}, {"nsec", nsec}};
}

struct Quaternion {
  double x = 0.0, y = 0.0, z = 0.0, w = 1.0;
};

/// A rotation by `a` about z.
Quaternion about_z(double a) { return {0.0, 0.0, std::sin(0.5 * a), std::cos(0.5 * a)}; }

/// R = Rz(rz) Ry(ry) Rx(rx) as q = qz qy qx (Hamilton products of the elementary turns).
Quaternion from_zyx(double rx, double ry, double rz) {
  const double cx = std::cos(0.5 * rx), sx = std::sin(0.5 * rx);
  const double cy = std::cos(0.5 * ry), sy = std::sin(0.5 * ry);
  const double cz = std::cos(0.5 * rz), sz = std::sin(0.5 * rz);
  return {cz * cy * sx - sz * sy * cx, cz * sy * cx + sz * cy * sx, sz * cy * cx - cz * sy * sx,
          cz * cy * cx + sz * sy * sx};
}

FrameTransform make(std::string_view parent, std::string_view child, double x, double y, double z,
                    Quaternion q) {
  return {parent, child, finite(x), finite(y), finite(z), q.x, q.y, q.z, q.w};
}

json transform(const json& time, const FrameTransform& f) {
  return {{"timestamp", time},
          {"parent_frame_id", f.parent},
          {"child_frame_id", f.child},
          {"translation", {{"x", f.x_m}, {"y", f.y_m}, {"z", f.z_m}}},
          {"rotation", {{"x", f.qx}, {"y", f.qy}, {"z", f.qz}, {"w", f.qw}}}};
}

json box(double cx, double cy, double cz, double sx, double sy, double sz, std::array<double, 4> rgba) {
  return {{"pose",
           {{"position", {{"x", cx}, {"y", cy}, {"z", cz}}},
            {"orientation", {{"x", 0.0}, {"y", 0.0}, {"z", 0.0}, {"w", 1.0}}}}},
          {"size", {{"x", sx}, {"y", sy}, {"z", sz}}},
          {"color", {{"r", rgba[0]}, {"g", rgba[1]}, {"b", rgba[2]}, {"a", rgba[3]}}}};
}

/// A scene entity holding boxes only, in `frame`, kept until replaced (lifetime 0).
json entity(const json& time, const char* frame, const char* id, json cubes) {
  const json none = json::array();
  return {
      {"timestamp", time},    {"frame_id", frame}, {"id", id},       {"lifetime", {{"sec", 0}, {"nsec", 0}}},
      {"frame_locked", true}, {"metadata", none},  {"arrows", none}, {"cubes", std::move(cubes)},
      {"spheres", none},      {"cylinders", none}, {"lines", none},  {"triangles", none},
      {"texts", none},        {"models", none}};
}

}  // namespace

RobotFrames::RobotFrames(const platform::TelemetrySchema& schema)
    : x_(schema.index("measured_x_m")),
      y_(schema.index("measured_y_m")),
      z_(schema.index("measured_z_m")),
      theta_(schema.index("measured_theta_rad")),
      opening_(schema.index("gripper_opening_m")) {
  const auto px = schema.find("part_x_m"), py = schema.find("part_y_m"), pz = schema.find("part_z_m"),
             yaw = schema.find("part_yaw_rad");
  if (px && py && pz && yaw) part_ = PartChannels{*px, *py, *pz, *yaw};
  const auto qx = schema.find("positioner_x_m"), qy = schema.find("positioner_y_m"),
             qz = schema.find("positioner_z_m"), rx = schema.find("positioner_rx_rad"),
             ry = schema.find("positioner_ry_rad"), rz = schema.find("positioner_rz_rad");
  if (qx && qy && qz && rx && ry && rz) positioner_ = PositionerChannels{*qx, *qy, *qz, *rx, *ry, *rz};
}

bool RobotFrames::fits(const platform::TelemetrySchema& schema) {
  for (const char* name :
       {"measured_x_m", "measured_y_m", "measured_z_m", "measured_theta_rad", "gripper_opening_m"})
    if (!schema.find(name)) return false;
  return true;
}

std::size_t RobotFrames::transforms(const platform::TelemetrySample& s, FrameTransforms& out) const {
  const double half = 0.5 * std::max(0.0, finite(s[opening_]));
  std::size_t n = 0;
  out[n++] = make("world", "tool", s[x_], s[y_], s[z_], {});
  out[n++] = make("tool", "gripper", 0.0, 0.0, 0.0, about_z(finite(s[theta_])));
  out[n++] = make("gripper", "finger_left", 0.0, half, 0.0, {});
  out[n++] = make("gripper", "finger_right", 0.0, -half, 0.0, {});
  if (part_)
    out[n++] = make("world", "part", s[part_->x], s[part_->y], s[part_->z], about_z(finite(s[part_->yaw])));
  if (positioner_) {
    const PositionerChannels& c = *positioner_;
    out[n++] = make("world", "positioner", s[c.x], s[c.y], s[c.z],
                    from_zyx(finite(s[c.rx]), finite(s[c.ry]), finite(s[c.rz])));
  }
  return n;
}

void RobotFrames::transforms_json(const platform::TelemetrySample& s, std::string& out) const {
  const json t = stamp(s[0]);
  FrameTransforms f;
  const std::size_t n = transforms(s, f);
  json list = json::array();
  for (std::size_t i = 0; i < n; ++i) list.push_back(transform(t, f[i]));
  out = json{{"transforms", std::move(list)}}.dump();
}

std::string RobotFrames::scene_update_json(const RobotBodies& b, double t_s) const {
  const json t = stamp(t_s);
  const std::array<double, 4> steel{0.62, 0.66, 0.70, 1.0}, brass{0.85, 0.65, 0.25, 1.0};
  json entities = json::array();
  // Each finger hangs from the tool point: its box's top at the tool point's height.
  const double w = b.finger_width_m, l = b.finger_length_m;
  if (w > 0.0 && l > 0.0) {
    entities.push_back(
        entity(t, "finger_left", "finger_left", json::array({box(0, 0, -0.5 * l, w, w, l, steel)})));
    entities.push_back(
        entity(t, "finger_right", "finger_right", json::array({box(0, 0, -0.5 * l, w, w, l, steel)})));
  }
  // The part's pose is its base's centre: the box stands on it.
  if (part_ && b.part_side_m > 0.0 && b.part_height_m > 0.0)
    entities.push_back(entity(t, "part", "part",
                              json::array({box(0, 0, 0.5 * b.part_height_m, b.part_side_m, b.part_side_m,
                                               b.part_height_m, brass)})));
  return json{{"deletions", json::array()}, {"entities", std::move(entities)}}.dump();
}

std::string RobotFrames::transforms_schema() {
  const json number = {{"type", "number"}};
  const json time = {{"type", "object"},
                     {"properties", {{"sec", {{"type", "integer"}}}, {"nsec", {{"type", "integer"}}}}}};
  const json xyz = {{"type", "object"}, {"properties", {{"x", number}, {"y", number}, {"z", number}}}};
  const json quat = {{"type", "object"},
                     {"properties", {{"x", number}, {"y", number}, {"z", number}, {"w", number}}}};
  const json tf = {{"type", "object"},
                   {"properties",
                    {{"timestamp", time},
                     {"parent_frame_id", {{"type", "string"}}},
                     {"child_frame_id", {{"type", "string"}}},
                     {"translation", xyz},
                     {"rotation", quat}}}};
  return json{{"title", "foxglove.FrameTransforms"},
              {"type", "object"},
              {"properties", {{"transforms", {{"type", "array"}, {"items", tf}}}}}}
      .dump();
}

std::string RobotFrames::scene_update_schema() {
  const json array = {{"type", "array"}};
  const json entity = {{"type", "object"},
                       {"properties",
                        {{"timestamp", {{"type", "object"}}},
                         {"frame_id", {{"type", "string"}}},
                         {"id", {{"type", "string"}}},
                         {"lifetime", {{"type", "object"}}},
                         {"frame_locked", {{"type", "boolean"}}},
                         {"metadata", array},
                         {"arrows", array},
                         {"cubes", array},
                         {"spheres", array},
                         {"cylinders", array},
                         {"lines", array},
                         {"triangles", array},
                         {"texts", array},
                         {"models", array}}}};
  return json{{"title", "foxglove.SceneUpdate"},
              {"type", "object"},
              {"properties", {{"deletions", array}, {"entities", {{"type", "array"}, {"items", entity}}}}}}
      .dump();
}

}  // namespace mc::live

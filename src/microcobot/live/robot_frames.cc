#include "microcobot/live/robot_frames.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Geometry>
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

/// The shortest rotation taking z onto the unit vector `v`: q = [z x v, 1 + z . v] normalised
/// (half the angle between them); half a turn about x when v = -z.
Quaternion z_onto(const Eigen::Vector3d& v) {
  const double w = 1.0 + v.z();
  if (w < 1e-12) return {1.0, 0.0, 0.0, 0.0};
  const double n = std::sqrt(v.x() * v.x() + v.y() * v.y() + w * w);
  return {-v.y() / n, v.x() / n, 0.0, w / n};
}

// The parallel positioner's frames: names are literals (FrameTransform holds views).
constexpr std::string_view kCarriageFrames[] = {"carriage_0", "carriage_1", "carriage_2"};
constexpr std::string_view kLegFrames[] = {"leg_0", "leg_1", "leg_2"};
static_assert(std::size(kLegFrames) == motion::kParallelLegs &&
              std::size(kCarriageFrames) == motion::kParallelLegs);

// The positioner's bodies where its geometry says nothing (parallel_geometry.h): each carriage is
// two stacked SLC-1720 (17 mm wide), its joint 17 mm above the base's underside.
constexpr double kCarriageWidth_m = 17e-3;
constexpr double kBaseUnderside_m = 17e-3;  // below the carriages' joints
constexpr double kBaseThickness_m = 5e-3;   // the base plate, under the carriages
constexpr double kJointDiameter_m = 5e-3;   // the spherical and revolute joints
constexpr double kLinkDiameter_m = 3e-3;    // the rigid legs
constexpr double kPlateThickness_m = 4e-3;  // the moving platform's top plate, under {P}'s origin
constexpr double kPlateMargin_m = 6e-3;     // the plate beyond the revolute joints' radius
constexpr double kPivotDiameter_m = 3e-3;   // the marker of {P}'s origin

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

using Rgba = std::array<double, 4>;

json pose(const Eigen::Vector3d& c, Quaternion q = {}) {
  return {{"position", {{"x", c.x()}, {"y", c.y()}, {"z", c.z()}}},
          {"orientation", {{"x", q.x}, {"y", q.y}, {"z", q.z}, {"w", q.w}}}};
}
json color(const Rgba& rgba) { return {{"r", rgba[0]}, {"g", rgba[1]}, {"b", rgba[2]}, {"a", rgba[3]}}; }

json box(double cx, double cy, double cz, double sx, double sy, double sz, const Rgba& rgba,
         Quaternion q = {}) {
  return {
      {"pose", pose({cx, cy, cz}, q)}, {"size", {{"x", sx}, {"y", sy}, {"z", sz}}}, {"color", color(rgba)}};
}

/// A straight cylinder of `diameter` and `length` along its pose's z, centred at `c`.
json cylinder(const Eigen::Vector3d& c, double diameter, double length, const Rgba& rgba, Quaternion q = {}) {
  return {{"pose", pose(c, q)},
          {"size", {{"x", diameter}, {"y", diameter}, {"z", length}}},
          {"bottom_scale", 1.0},
          {"top_scale", 1.0},
          {"color", color(rgba)}};
}

json sphere(const Eigen::Vector3d& c, double diameter, const Rgba& rgba) {
  return {{"pose", pose(c)},
          {"size", {{"x", diameter}, {"y", diameter}, {"z", diameter}}},
          {"color", color(rgba)}};
}

/// A scene entity in `frame`, kept until replaced (lifetime 0).
json entity(const json& time, std::string_view frame, std::string_view id, json cubes,
            json cylinders = json::array(), json spheres = json::array()) {
  const json none = json::array();
  return {{"timestamp", time},
          {"frame_id", frame},
          {"id", id},
          {"lifetime", {{"sec", 0}, {"nsec", 0}}},
          {"frame_locked", true},
          {"metadata", none},
          {"arrows", none},
          {"cubes", std::move(cubes)},
          {"spheres", std::move(spheres)},
          {"cylinders", std::move(cylinders)},
          {"lines", none},
          {"triangles", none},
          {"texts", none},
          {"models", none}};
}

}  // namespace

RobotFrames::RobotFrames(const platform::TelemetrySchema& schema,
                         const motion::ParallelGeometryParams* positioner)
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
  if (positioner_ && positioner) {
    kinematics_.emplace(*positioner);
    for (int i = 0; i < motion::kParallelLegs; ++i) {
      const Eigen::Vector3d& e_r = kinematics_->geometry().legs[i].e_r;
      leg_heading_rad_[i] = std::atan2(e_r.y(), e_r.x());
    }
  }
}

std::size_t RobotFrames::positioner_frames(const platform::TelemetrySample& s, FrameTransforms& out,
                                           std::size_t n) const {
  const motion::ParallelGeometry& g = kinematics_->geometry();
  out[n++] = make("world", "positioner_base", 0.0, 0.0, -g.home_height_m, {});
  const PositionerChannels& c = *positioner_;
  motion::PlatformTransform T;
  T.R = motion::smarpod_rotation(finite(s[c.rx]), finite(s[c.ry]), finite(s[c.rz]));
  T.d = {finite(s[c.x]), finite(s[c.y]), finite(s[c.z])};
  motion::LegClosure legs[motion::kParallelLegs];
  motion::LegCoordinates q;
  if (!kinematics_->closures(T, legs, q)) return n;  // no legs close there: a viewer keeps the last
  for (int i = 0; i < motion::kParallelLegs; ++i) {
    const Eigen::Vector3d& b = legs[i].carriage_m;
    out[n++] = make("positioner_base", kCarriageFrames[i], b.x(), b.y(), b.z(), about_z(leg_heading_rad_[i]));
    out[n++] = make("positioner_base", kLegFrames[i], b.x(), b.y(), b.z(),
                    z_onto((legs[i].joint_m - b).normalized()));
  }
  return n;
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
    if (kinematics_) n = positioner_frames(s, out, n);
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
  if (kinematics_) {
    const motion::ParallelGeometry& g = kinematics_->geometry();
    const motion::ParallelGeometryParams& p = g.params;
    const Rgba aluminium{0.78, 0.80, 0.83, 1.0}, anthracite{0.30, 0.32, 0.36, 1.0},
        joint{0.18, 0.18, 0.20, 1.0}, anodised{0.35, 0.55, 0.85, 1.0}, pivot{0.90, 0.20, 0.15, 1.0};
    // The base plate under the carriages, wide enough for their stroke (two SLC-1720 stacked).
    const double base_d = 2.0 * (p.base_radius_m + 0.5 * p.stroke_m + 0.5 * kCarriageWidth_m);
    const double carriage_h = kBaseUnderside_m - kBaseThickness_m - 0.5 * kJointDiameter_m;
    entities.push_back(entity(t, "positioner_base", "positioner_base", json::array(),
                              json::array({cylinder({0, 0, -kBaseUnderside_m + 0.5 * kBaseThickness_m},
                                                    base_d, kBaseThickness_m, aluminium)})));
    for (int i = 0; i < motion::kParallelLegs; ++i) {
      // The carriage's block under its spherical joint, the joint on top.
      entities.push_back(
          entity(t, kCarriageFrames[i], kCarriageFrames[i],
                 json::array({box(0, 0, -0.5 * kJointDiameter_m - 0.5 * carriage_h, kCarriageWidth_m,
                                  kCarriageWidth_m, carriage_h, anthracite)}),
                 json::array(), json::array({sphere({0, 0, 0}, kJointDiameter_m, joint)})));
      // The rigid leg, from B_i (its frame's origin) to P_i = (0, 0, L).
      entities.push_back(entity(
          t, kLegFrames[i], kLegFrames[i], json::array(),
          json::array({cylinder({0, 0, 0.5 * g.leg_length_m}, kLinkDiameter_m, g.leg_length_m, steel)})));
    }
    // The moving platform in {P}: its top plate under the origin, a post down to each revolute
    // joint p_i (o below the origin), the joint's axis a_i, and {P}'s origin.
    json cubes = json::array(), cylinders = json::array();
    cylinders.push_back(cylinder({0, 0, -0.5 * kPlateThickness_m},
                                 2.0 * (p.platform_radius_m + kPlateMargin_m), kPlateThickness_m, anodised));
    const double post = p.top_offset_m - kPlateThickness_m;
    for (const motion::LegGeometry& leg : g.legs) {
      const Eigen::Vector3d& j = leg.platform_m;
      if (post > 0.0)
        cubes.push_back(box(j.x(), j.y(), -kPlateThickness_m - 0.5 * post, kJointDiameter_m, kJointDiameter_m,
                            post, anodised, about_z(std::atan2(leg.e_r.y(), leg.e_r.x()))));
      cylinders.push_back(cylinder(j, kJointDiameter_m, 2.0 * kJointDiameter_m, joint, z_onto(leg.axis)));
    }
    entities.push_back(entity(t, "positioner", "positioner", std::move(cubes), std::move(cylinders),
                              json::array({sphere({0, 0, 0}, kPivotDiameter_m, pivot)})));
  }
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

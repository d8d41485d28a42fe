#include "microcobot/net/ros_mapping.h"

#include <cmath>
#include <cstring>
#include <limits>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"

namespace mc::net {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

NetSample pose_sample() {
  NetSample s;
  s.channel = Channel::kMeasuredPose;
  s.stamp_ns = 1'700'000'000'123'456'789;
  s.xyz = {1e-3, -2e-4, 5e-6};
  return s;
}

TEST(RosTime, SplitsNanosecondsIntoSecAndNanosec) {
  const auto t = to_ros_time(1'500'000'000);
  EXPECT_EQ(t.sec_, 1);
  EXPECT_EQ(t.nanosec_, 500'000'000u);
  std::int64_t back = 0;
  ASSERT_TRUE(from_ros_time(t, back));
  EXPECT_EQ(back, 1'500'000'000);
  // Negative times do not exist in ROS 2: clamped when sending.
  EXPECT_EQ(to_ros_time(-5).sec_, 0);
  EXPECT_EQ(to_ros_time(-5).nanosec_, 0u);
}

TEST(RosTime, RefusesNanosecOfASecondOrMoreAndNegativeSeconds) {
  std::int64_t ns = 0;
  EXPECT_FALSE(from_ros_time({1, 1'000'000'000u}, ns));
  EXPECT_FALSE(from_ros_time({-1, 0u}, ns));
  EXPECT_TRUE(from_ros_time({0, 999'999'999u}, ns));
  EXPECT_EQ(ns, 999'999'999);
}

TEST(RosMapping, PoseStampedRoundTripsInMetresWithTheStageFrameAndIdentityOrientation) {
  geometry_msgs_msg_dds__PoseStamped_ m;
  to_ros(pose_sample(), m);
  EXPECT_STREQ(m.header_.frame_id_, kStageFrame);
  EXPECT_EQ(m.header_.stamp_.sec_, 1'700'000'000);
  EXPECT_EQ(m.header_.stamp_.nanosec_, 123'456'789u);
  EXPECT_DOUBLE_EQ(m.pose_.position_.x_, 1e-3);
  EXPECT_DOUBLE_EQ(m.pose_.orientation_.w_, 1.0);
  EXPECT_DOUBLE_EQ(m.pose_.orientation_.x_, 0.0);
  NetSample back;
  ASSERT_EQ(from_ros(m, Channel::kTarget, NetLimits{}, back), Rejection::kNone);
  EXPECT_EQ(back.channel, Channel::kTarget);
  EXPECT_EQ(back.stamp_ns, pose_sample().stamp_ns);
  EXPECT_EQ(back.xyz, pose_sample().xyz);
}

// The rotary axis' angle rides as the pose's orientation, a rotation about z.
TEST(RosMapping, APosesYawIsARotationAboutZAndAnyOtherRotationIsRefused) {
  NetSample s = pose_sample();
  s.yaw_rad = -0.75;
  geometry_msgs_msg_dds__PoseStamped_ m;
  to_ros(s, m);
  EXPECT_NEAR(m.pose_.orientation_.z_, std::sin(-0.375), 1e-15);
  EXPECT_NEAR(m.pose_.orientation_.w_, std::cos(-0.375), 1e-15);
  NetSample back;
  ASSERT_EQ(from_ros(m, Channel::kMeasuredPose, NetLimits{}, back), Rejection::kNone);
  EXPECT_NEAR(back.yaw_rad, -0.75, 1e-12);
  // The same rotation written with the opposite sign (q and -q): the same yaw.
  m.pose_.orientation_.z_ = -m.pose_.orientation_.z_, m.pose_.orientation_.w_ = -m.pose_.orientation_.w_;
  ASSERT_EQ(from_ros(m, Channel::kMeasuredPose, NetLimits{}, back), Rejection::kNone);
  EXPECT_NEAR(back.yaw_rad, -0.75, 1e-12);
  // A ROS tool's default (all zero) is the identity.
  m.pose_.orientation_ = {};
  ASSERT_EQ(from_ros(m, Channel::kTarget, NetLimits{}, back), Rejection::kNone);
  EXPECT_EQ(back.yaw_rad, 0.0);
  // A tilt, a quaternion that is not a rotation, a NaN: refused.
  m.pose_.orientation_.x_ = std::sin(0.05), m.pose_.orientation_.w_ = std::cos(0.05);
  EXPECT_EQ(from_ros(m, Channel::kTarget, NetLimits{}, back), Rejection::kOutOfRange);
  m.pose_.orientation_ = {};
  m.pose_.orientation_.w_ = 2.0;
  EXPECT_EQ(from_ros(m, Channel::kTarget, NetLimits{}, back), Rejection::kOutOfRange);
  m.pose_.orientation_.z_ = kNaN;
  EXPECT_EQ(from_ros(m, Channel::kTarget, NetLimits{}, back), Rejection::kNonFinite);
}

TEST(RosMapping, RefusesNonFiniteOutOfRangeAndBadStampsInPoses) {
  geometry_msgs_msg_dds__PoseStamped_ m;
  NetSample out;
  to_ros(pose_sample(), m);
  m.pose_.position_.y_ = kNaN;
  EXPECT_EQ(from_ros(m, Channel::kTarget, NetLimits{}, out), Rejection::kNonFinite);
  m.pose_.position_.y_ = kInf;
  EXPECT_EQ(from_ros(m, Channel::kTarget, NetLimits{}, out), Rejection::kNonFinite);
  m.pose_.position_.y_ = 0.2;  // 20 cm: beyond the stage
  EXPECT_EQ(from_ros(m, Channel::kTarget, NetLimits{}, out), Rejection::kOutOfRange);
  m.pose_.position_.y_ = 0.0;
  m.header_.stamp_.nanosec_ = 2'000'000'000u;
  EXPECT_EQ(from_ros(m, Channel::kTarget, NetLimits{}, out), Rejection::kBadStamp);
}

TEST(RosMapping, WrenchStampedCarriesNewtonsAndRefusesExcessiveForces) {
  NetSample s = pose_sample();
  s.channel = Channel::kContactForce;
  s.xyz = {0.0, 0.0, -2.5e-3};
  geometry_msgs_msg_dds__WrenchStamped_ m;
  to_ros(s, m);
  EXPECT_DOUBLE_EQ(m.wrench_.force_.z_, -2.5e-3);
  EXPECT_DOUBLE_EQ(m.wrench_.torque_.z_, 0.0);
  NetSample back;
  ASSERT_EQ(from_ros(m, Channel::kContactForce, NetLimits{}, back), Rejection::kNone);
  EXPECT_DOUBLE_EQ(back.xyz[2], -2.5e-3);
  m.wrench_.force_.x_ = 50.0;
  EXPECT_EQ(from_ros(m, Channel::kContactForce, NetLimits{}, back), Rejection::kOutOfRange);
  m.wrench_.force_.x_ = -kInf;
  EXPECT_EQ(from_ros(m, Channel::kContactForce, NetLimits{}, back), Rejection::kNonFinite);
}

TEST(RosMapping, PortEnergiesAreNonNegativeFiniteJoulesWithinTheLimit) {
  NetSample s = pose_sample();
  s.channel = Channel::kSlavePortEnergy;
  s.xyz = {1.5e-6, 0.0, 2e-9};
  geometry_msgs_msg_dds__Vector3Stamped_ m;
  to_ros(s, m);
  EXPECT_DOUBLE_EQ(m.vector_.x_, 1.5e-6);
  EXPECT_STREQ(m.header_.frame_id_, kStageFrame);
  NetSample back;
  ASSERT_EQ(from_ros(m, Channel::kSlavePortEnergy, NetLimits{}, back), Rejection::kNone);
  EXPECT_EQ(back.xyz, s.xyz);
  EXPECT_EQ(back.stamp_ns, s.stamp_ns);
  m.vector_.y_ = -1e-12;  // energy put into the channel never goes below zero
  EXPECT_EQ(from_ros(m, Channel::kSlavePortEnergy, NetLimits{}, back), Rejection::kOutOfRange);
  m.vector_.y_ = 2e3;
  EXPECT_EQ(from_ros(m, Channel::kSlavePortEnergy, NetLimits{}, back), Rejection::kOutOfRange);
  m.vector_.y_ = kNaN;
  EXPECT_EQ(from_ros(m, Channel::kSlavePortEnergy, NetLimits{}, back), Rejection::kNonFinite);
}

TEST(RosMapping, JointStateHoldsTheGripperOpeningAsOneNamedJoint) {
  NetSample s;
  s.channel = Channel::kGripperOpening;
  s.stamp_ns = 42;
  s.scalar = 3e-4;
  JointStateBuffer buf;
  sensor_msgs_msg_dds__JointState_ m;
  to_ros(s, buf, m);
  ASSERT_EQ(m.name_._length, 1u);
  EXPECT_STREQ(m.name_._buffer[0], kGripperJoint);
  ASSERT_EQ(m.position_._length, 1u);
  EXPECT_DOUBLE_EQ(m.position_._buffer[0], 3e-4);
  EXPECT_EQ(m.velocity_._length, 0u);
  NetSample back;
  ASSERT_EQ(from_ros(m, Channel::kGripperOpening, NetLimits{}, back), Rejection::kNone);
  EXPECT_DOUBLE_EQ(back.scalar, 3e-4);
  EXPECT_EQ(back.stamp_ns, 42);
}

TEST(RosMapping, RefusesJointStatesOfTheWrongSizeOrWithBadValues) {
  NetSample s;
  s.scalar = 1e-4;
  JointStateBuffer buf;
  sensor_msgs_msg_dds__JointState_ m;
  NetSample out;
  to_ros(s, buf, m);
  double two[2] = {1e-4, 2e-4};
  m.position_._buffer = two;
  m.position_._length = 2;
  EXPECT_EQ(from_ros(m, Channel::kGripperTarget, NetLimits{}, out), Rejection::kBadSize);
  m.position_._length = 0;
  EXPECT_EQ(from_ros(m, Channel::kGripperTarget, NetLimits{}, out), Rejection::kBadSize);
  m.position_._length = 1;
  m.position_._buffer = nullptr;
  EXPECT_EQ(from_ros(m, Channel::kGripperTarget, NetLimits{}, out), Rejection::kBadSize);
  double bad[1] = {-1e-4};  // a negative opening
  m.position_._buffer = bad;
  EXPECT_EQ(from_ros(m, Channel::kGripperTarget, NetLimits{}, out), Rejection::kOutOfRange);
  bad[0] = kNaN;
  EXPECT_EQ(from_ros(m, Channel::kGripperTarget, NetLimits{}, out), Rejection::kNonFinite);
  bad[0] = 1e-4;
  double nan_velocity[1] = {kNaN};
  m.velocity_._buffer = nan_velocity;
  m.velocity_._length = 1;
  EXPECT_EQ(from_ros(m, Channel::kGripperTarget, NetLimits{}, out), Rejection::kNonFinite);
  m.velocity_._length = 0;
  EXPECT_EQ(from_ros(m, Channel::kGripperTarget, NetLimits{}, out), Rejection::kNone);
}

TEST(RosMapping, BoolIsZeroOrOne) {
  NetSample s;
  s.scalar = 1.0;
  std_msgs_msg_dds__Bool_ m{};
  to_ros(s, m);
  EXPECT_TRUE(m.data_);
  NetSample back;
  ASSERT_EQ(from_ros(m, Channel::kEstop, back), Rejection::kNone);
  EXPECT_EQ(back.scalar, 1.0);
  EXPECT_EQ(back.channel, Channel::kEstop);
}

TEST(RosMapping, DiagnosticsReportEachSlaveDeviceWithItsLevelAndLifecycle) {
  NetSample s;
  s.channel = Channel::kSlaveDiagnostics;
  s.stamp_ns = 2'000'000'001;
  s.xyz = {2, 2, 3};  // axes active, z in fault
  s.scalar = 1;       // gripper inactive
  DiagnosticsBuffer buf;
  diagnostic_msgs_msg_dds__DiagnosticArray_ m;
  to_ros(s, buf, m);
  ASSERT_EQ(m.status_._length, 4u);
  EXPECT_STREQ(m.status_._buffer[0].name_, "microcobot/slave/axis_x");
  EXPECT_EQ(m.status_._buffer[0].level_, 0);  // OK
  EXPECT_STREQ(m.status_._buffer[0].message_, "active");
  EXPECT_EQ(m.status_._buffer[2].level_, 2);  // ERROR
  EXPECT_STREQ(m.status_._buffer[2].message_, "fault");
  EXPECT_EQ(m.status_._buffer[3].level_, 1);  // WARN
  EXPECT_STREQ(m.status_._buffer[3].hardware_id_, "microcobot_slave");
  NetSample back;
  ASSERT_EQ(from_ros(m, Channel::kSlaveDiagnostics, back), Rejection::kNone);
  EXPECT_EQ(back.xyz, s.xyz);
  EXPECT_EQ(back.scalar, s.scalar);
  EXPECT_EQ(back.stamp_ns, s.stamp_ns);
  // Refused: a level that contradicts the message, an unknown state, a missing device.
  buf.status[1].level_ = 0;
  buf.status[1].message_ = const_cast<char*>("fault");
  EXPECT_EQ(from_ros(m, Channel::kSlaveDiagnostics, back), Rejection::kOutOfRange);
  buf.status[1].message_ = const_cast<char*>("exploded");
  EXPECT_EQ(from_ros(m, Channel::kSlaveDiagnostics, back), Rejection::kOutOfRange);
  to_ros(s, buf, m);
  m.status_._length = 3;
  EXPECT_EQ(from_ros(m, Channel::kSlaveDiagnostics, back), Rejection::kBadSize);
  m.status_._length = 4;
  buf.status[0].name_ = const_cast<char*>("someone/else");
  EXPECT_EQ(from_ros(m, Channel::kSlaveDiagnostics, back), Rejection::kBadSize);
}

TEST(NetLimits, RefusesNonPositiveOrNonFiniteBounds) {
  NetLimits l;
  EXPECT_NO_THROW(l.validate());
  l.max_abs_force_N = 0.0;
  EXPECT_THROW(l.validate(), InvalidParams);
  l = NetLimits{};
  l.max_abs_position_m = kNaN;
  EXPECT_THROW(l.validate(), InvalidParams);
  l = NetLimits{};
  l.max_port_energy_J = -1.0;
  EXPECT_THROW(l.validate(), InvalidParams);
}

}  // namespace
}  // namespace mc::net

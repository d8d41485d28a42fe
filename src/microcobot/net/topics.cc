#include "microcobot/net/topics.h"

#include <cmath>

#include "ros2_messages.h"

namespace mc::net {

namespace {

constexpr std::string_view kPoseStamped = "geometry_msgs::msg::dds_::PoseStamped_";
constexpr std::string_view kWrenchStamped = "geometry_msgs::msg::dds_::WrenchStamped_";
constexpr std::string_view kJointState = "sensor_msgs::msg::dds_::JointState_";
constexpr std::string_view kBool = "std_msgs::msg::dds_::Bool_";
constexpr std::string_view kVector3Stamped = "geometry_msgs::msg::dds_::Vector3Stamped_";
constexpr std::string_view kDiagnosticArray = "diagnostic_msgs::msg::dds_::DiagnosticArray_";

constexpr TopicSpec state(Channel c, std::string_view ros, std::string_view dds, RosType type,
                          std::string_view type_name, Role publisher, std::string_view unit) {
  return {c,
          ros,
          dds,
          type,
          type_name,
          publisher,
          kStateRate_Hz,
          Reliability::kBestEffort,
          Durability::kVolatile,
          1,
          kStateDeadline_s,
          kStateLease_s,
          unit};
}

constexpr TopicSpec latched(Channel c, std::string_view ros, std::string_view dds, Role publisher) {
  return {c,
          ros,
          dds,
          RosType::kBool,
          kBool,
          publisher,
          0.0,
          Reliability::kReliable,
          Durability::kTransientLocal,
          1,
          0.0,
          0.0,
          "1 (true/false)"};
}

constexpr std::array<TopicSpec, kChannelCount> kTable{{
    state(Channel::kTarget, "/microcobot/slave/target_pose", "rt/microcobot/slave/target_pose",
          RosType::kPoseStamped, kPoseStamped, Role::kMaster, "m"),
    state(Channel::kMeasuredPose, "/microcobot/slave/pose", "rt/microcobot/slave/pose", RosType::kPoseStamped,
          kPoseStamped, Role::kSlave, "m"),
    state(Channel::kContactForce, "/microcobot/slave/contact_wrench", "rt/microcobot/slave/contact_wrench",
          RosType::kWrenchStamped, kWrenchStamped, Role::kSlave, "N"),
    state(Channel::kGripForce, "/microcobot/slave/grip_wrench", "rt/microcobot/slave/grip_wrench",
          RosType::kWrenchStamped, kWrenchStamped, Role::kSlave, "N"),
    state(Channel::kGripperTarget, "/microcobot/slave/gripper/target", "rt/microcobot/slave/gripper/target",
          RosType::kJointState, kJointState, Role::kMaster, "m"),
    state(Channel::kGripperOpening, "/microcobot/slave/gripper/state", "rt/microcobot/slave/gripper/state",
          RosType::kJointState, kJointState, Role::kSlave, "m"),
    latched(Channel::kEstop, "/microcobot/estop", "rt/microcobot/estop", Role::kMaster),
    latched(Channel::kEngaged, "/microcobot/master/engaged", "rt/microcobot/master/engaged", Role::kMaster),
    // ROS 2's /diagnostics: reliable, keep last 1 (a late state is still worth having; the newest
    // is the one that counts), volatile (states are republished at 10 Hz).
    {Channel::kSlaveDiagnostics, "/diagnostics", "rt/diagnostics", RosType::kDiagnosticArray,
     kDiagnosticArray, Role::kSlave, kDiagnosticsRate_Hz, Reliability::kReliable, Durability::kVolatile, 1,
     0.0, 0.0, "level 0 OK (active), 1 WARN (inactive), 2 ERROR (fault), 3 STALE (unconfigured)"},
    // Time-domain passivity: each end's input energy travels with its state, at its rate (a
    // lost sample only delays the energy it carried: the next one holds the total).
    state(Channel::kMasterPortEnergy, "/microcobot/master/port_energy", "rt/microcobot/master/port_energy",
          RosType::kVector3Stamped, kVector3Stamped, Role::kMaster, "J (x, y, z: the stage axes' ports)"),
    state(Channel::kSlavePortEnergy, "/microcobot/slave/port_energy", "rt/microcobot/slave/port_energy",
          RosType::kVector3Stamped, kVector3Stamped, Role::kSlave, "J (x, y, z: the stage axes' ports)"),
    state(Channel::kMasterGripperPortEnergy, "/microcobot/master/gripper/port_energy",
          "rt/microcobot/master/gripper/port_energy", RosType::kVector3Stamped, kVector3Stamped,
          Role::kMaster, "J (x: the gripper's opening port; y, z: 0)"),
    state(Channel::kSlaveGripperPortEnergy, "/microcobot/slave/gripper/port_energy",
          "rt/microcobot/slave/gripper/port_energy", RosType::kVector3Stamped, kVector3Stamped, Role::kSlave,
          "J (x: the gripper's opening port; y, z: 0)"),
    latched(Channel::kGripperShake, "/microcobot/master/gripper/shake", "rt/microcobot/master/gripper/shake",
            Role::kMaster),
}};

constexpr bool table_is_indexed_by_channel() {
  for (std::size_t i = 0; i < kTable.size(); ++i) {
    if (static_cast<std::size_t>(kTable[i].channel) != i) return false;
  }
  return true;
}
static_assert(table_is_indexed_by_channel(), "topic table order must follow Channel");

dds_duration_t to_duration(double s) { return static_cast<dds_duration_t>(std::llround(s * 1e9)); }

}  // namespace

const std::array<TopicSpec, kChannelCount>& topic_table() { return kTable; }

const TopicSpec& topic(Channel c) { return kTable[static_cast<std::size_t>(c)]; }

dds_qos_t* make_qos(const TopicSpec& spec) {
  dds_qos_t* qos = dds_create_qos();
  if (spec.reliability == Reliability::kReliable) {
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  } else {
    dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
  }
  dds_qset_durability(qos, spec.durability == Durability::kTransientLocal ? DDS_DURABILITY_TRANSIENT_LOCAL
                                                                          : DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, spec.depth);
  if (spec.deadline_s > 0) dds_qset_deadline(qos, to_duration(spec.deadline_s));
  if (spec.liveliness_lease_s > 0)
    dds_qset_liveliness(qos, DDS_LIVELINESS_AUTOMATIC, to_duration(spec.liveliness_lease_s));
  return qos;
}

dds_qos_t* make_state_qos() { return make_qos(topic(Channel::kMeasuredPose)); }

const dds_topic_descriptor_t* descriptor(RosType type) {
  switch (type) {
    case RosType::kPoseStamped:
      return &geometry_msgs_msg_dds__PoseStamped__desc;
    case RosType::kWrenchStamped:
      return &geometry_msgs_msg_dds__WrenchStamped__desc;
    case RosType::kJointState:
      return &sensor_msgs_msg_dds__JointState__desc;
    case RosType::kBool:
      return &std_msgs_msg_dds__Bool__desc;
    case RosType::kDiagnosticArray:
      return &diagnostic_msgs_msg_dds__DiagnosticArray__desc;
    case RosType::kVector3Stamped:
      return &geometry_msgs_msg_dds__Vector3Stamped__desc;
  }
  return nullptr;
}

}  // namespace mc::net

#include "microcobot/net/topics.h"

#include <string>

#include <gtest/gtest.h>

namespace mc::net {
namespace {

TEST(TopicTable, DdsNamesAreRtPlusTheRosNameAndTypesAreRmwCycloneddsNames) {
  for (const TopicSpec& t : topic_table()) {
    SCOPED_TRACE(std::string(t.ros_name));
    ASSERT_EQ(t.ros_name.front(), '/');
    EXPECT_EQ(std::string(t.dds_name), "rt/" + std::string(t.ros_name.substr(1)));
    // The generated descriptor carries the very name a ROS 2 node's rmw_cyclonedds_cpp uses.
    EXPECT_EQ(std::string(descriptor(t.type)->m_typename), std::string(t.type_name));
    EXPECT_NE(std::string(t.type_name).find("::msg::dds_::"), std::string::npos);
    EXPECT_EQ(t.type_name.back(), '_');
  }
  EXPECT_EQ(topic(Channel::kMeasuredPose).type_name, "geometry_msgs::msg::dds_::PoseStamped_");
  EXPECT_EQ(topic(Channel::kContactForce).type_name, "geometry_msgs::msg::dds_::WrenchStamped_");
  EXPECT_EQ(topic(Channel::kGripperOpening).type_name, "sensor_msgs::msg::dds_::JointState_");
  EXPECT_EQ(topic(Channel::kEstop).type_name, "std_msgs::msg::dds_::Bool_");
}

TEST(TopicTable, StateIsBestEffortKeepLastOneAtOneKilohertzWithADeadline) {
  for (Channel c : {Channel::kTarget, Channel::kMeasuredPose, Channel::kContactForce, Channel::kGripForce,
                    Channel::kGripperTarget, Channel::kGripperOpening}) {
    const TopicSpec& t = topic(c);
    EXPECT_EQ(t.rate_Hz, 1000.0);
    EXPECT_EQ(t.reliability, Reliability::kBestEffort);
    EXPECT_EQ(t.durability, Durability::kVolatile);
    EXPECT_EQ(t.depth, 1);
    EXPECT_GT(t.deadline_s, 0.0);
    EXPECT_LE(t.deadline_s, 0.01);
    EXPECT_GT(t.liveliness_lease_s, 0.0);
  }
}

TEST(TopicTable, EstopAndModeChangesAreReliableAndTransientLocal) {
  for (Channel c : {Channel::kEstop, Channel::kEngaged}) {
    const TopicSpec& t = topic(c);
    EXPECT_EQ(t.reliability, Reliability::kReliable);
    EXPECT_EQ(t.durability, Durability::kTransientLocal);
    EXPECT_EQ(t.publisher, Role::kMaster);
  }
}

TEST(TopicTable, QosObjectsCarryTheTable) {
  dds_qos_t* q = make_qos(topic(Channel::kEstop));
  dds_reliability_kind_t kind{};
  dds_duration_t block = 0;
  ASSERT_TRUE(dds_qget_reliability(q, &kind, &block));
  EXPECT_EQ(kind, DDS_RELIABILITY_RELIABLE);
  dds_durability_kind_t dur{};
  ASSERT_TRUE(dds_qget_durability(q, &dur));
  EXPECT_EQ(dur, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_delete_qos(q);
  q = make_qos(topic(Channel::kTarget));
  ASSERT_TRUE(dds_qget_reliability(q, &kind, &block));
  EXPECT_EQ(kind, DDS_RELIABILITY_BEST_EFFORT);
  dds_duration_t deadline = 0;
  ASSERT_TRUE(dds_qget_deadline(q, &deadline));
  EXPECT_EQ(deadline, DDS_MSECS(10));
  dds_history_kind_t hist{};
  std::int32_t depth = 0;
  ASSERT_TRUE(dds_qget_history(q, &hist, &depth));
  EXPECT_EQ(hist, DDS_HISTORY_KEEP_LAST);
  EXPECT_EQ(depth, 1);
  dds_delete_qos(q);
}

TEST(TopicTable, ThePositionersPoseIsAStateTopicBesideTheCouplings) {
  const ObserverTopicSpec& t = kPositionerPoseTopic;
  EXPECT_EQ(std::string(t.dds_name), "rt/" + std::string(t.ros_name.substr(1)));
  EXPECT_EQ(std::string(descriptor(RosType::kPoseStamped)->m_typename), std::string(t.type_name));
  EXPECT_EQ(t.publisher, Role::kSlave);
  EXPECT_EQ(t.rate_Hz, topic(Channel::kMeasuredPose).rate_Hz);
  for (const TopicSpec& c : topic_table()) EXPECT_NE(c.ros_name, t.ros_name);  // not the link's
  // Its QoS is the state profile's, field by field.
  dds_qos_t* state = make_qos(topic(Channel::kMeasuredPose));
  dds_qos_t* q = make_state_qos();
  dds_reliability_kind_t kind{};
  dds_duration_t block = 0, deadline = 0;
  ASSERT_TRUE(dds_qget_reliability(q, &kind, &block));
  EXPECT_EQ(kind, DDS_RELIABILITY_BEST_EFFORT);
  ASSERT_TRUE(dds_qget_deadline(q, &deadline));
  EXPECT_EQ(deadline, DDS_MSECS(10));
  EXPECT_TRUE(dds_qos_equal(q, state));
  dds_delete_qos(q);
  dds_delete_qos(state);
}

}  // namespace
}  // namespace mc::net

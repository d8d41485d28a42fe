// The microscope's focus drive and turret on DDS (net/microscope_topics.h,
// net/microscope_link.h): the joint-state mapping and its refusals, and both ends over a real
// Cyclone domain of this test process.

#include "microcobot/net/microscope_link.h"

#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <vector>

#include <gtest/gtest.h>

#include "net/net_test_support.h"

namespace mc::net {
namespace {

// A JointState as a peer would write it: names and positions as given.
struct Message {
  std::vector<const char*> names;
  std::vector<double> positions;
  std::vector<double> velocities{};
  sensor_msgs_msg_dds__JointState_ m{};
  Message(std::vector<const char*> n, std::vector<double> p) : names(std::move(n)), positions(std::move(p)) {}
  const sensor_msgs_msg_dds__JointState_& build() {
    m = {};
    m.header_.stamp_ = {1, 5u};
    m.name_._length = static_cast<std::uint32_t>(names.size());
    m.name_._buffer = const_cast<char**>(names.data());
    m.position_._length = static_cast<std::uint32_t>(positions.size());
    m.position_._buffer = positions.data();
    m.velocity_._length = static_cast<std::uint32_t>(velocities.size());
    m.velocity_._buffer = velocities.data();
    return m;
  }
};

MicroscopeRejection read(Message msg, MicroscopeJoints& out) { return from_ros(msg.build(), out); }

TEST(MicroscopeTopics, AStateCarriesBothJointsAndReadsBack) {
  MicroscopeJoints j;
  j.has_focus = true;
  j.focus_z_m = 123.5e-6;
  j.objective = 3;
  j.stamp_ns = 1'700'000'000'000'000'042;
  MicroscopeJointBuffer buf;
  sensor_msgs_msg_dds__JointState_ m;
  to_ros(j, buf, m);
  ASSERT_EQ(m.name_._length, 2u);
  EXPECT_STREQ(m.name_._buffer[0], "focus_z");
  EXPECT_STREQ(m.name_._buffer[1], "objective_turret");
  EXPECT_EQ(m.position_._buffer[1], 3.0);
  MicroscopeJoints back;
  ASSERT_EQ(from_ros(m, back), MicroscopeRejection::kNone);
  EXPECT_TRUE(back.has_focus);
  EXPECT_EQ(back.focus_z_m, 123.5e-6);
  EXPECT_EQ(back.objective, 3);
  EXPECT_EQ(back.stamp_ns, j.stamp_ns);
}

TEST(MicroscopeTopics, ACommandMayNameEitherJointInAnyOrder) {
  MicroscopeJoints j;
  ASSERT_EQ(read({{"objective_turret", "focus_z"}, {2.0, -50e-6}}, j), MicroscopeRejection::kNone);
  EXPECT_EQ(j.objective, 2);
  EXPECT_EQ(j.focus_z_m, -50e-6);
  ASSERT_EQ(read({{"objective_turret"}, {1.0}}, j), MicroscopeRejection::kNone);
  EXPECT_FALSE(j.has_focus);
  EXPECT_EQ(j.objective, 1);
  ASSERT_EQ(read({{"focus_z"}, {0.2e-3}}, j), MicroscopeRejection::kNone);
  EXPECT_TRUE(j.has_focus);
  EXPECT_EQ(j.objective, -1);
}

TEST(MicroscopeTopics, RefusesWhatIsNotAMicroscopeCommandSayingWhy) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  MicroscopeJoints j;
  j.objective = 4;  // untouched by a refusal
  EXPECT_EQ(read({{}, {}}, j), MicroscopeRejection::kBadSize);
  EXPECT_EQ(read({{"focus_z"}, {}}, j), MicroscopeRejection::kBadSize);
  EXPECT_EQ(read({{"focus_z", "objective_turret", "focus_z"}, {0, 1, 0}}, j), MicroscopeRejection::kBadSize);
  EXPECT_EQ(read({{"gripper_opening"}, {1e-3}}, j), MicroscopeRejection::kUnknownJoint);
  EXPECT_EQ(read({{"focus_z", "focus_z"}, {0.0, 1e-6}}, j), MicroscopeRejection::kUnknownJoint);
  EXPECT_EQ(read({{"focus_z"}, {nan}}, j), MicroscopeRejection::kNonFinite);
  EXPECT_EQ(read({{"focus_z"}, {2.0}}, j), MicroscopeRejection::kOutOfRange);
  EXPECT_EQ(read({{"objective_turret"}, {1.5}}, j), MicroscopeRejection::kOutOfRange);
  EXPECT_EQ(read({{"objective_turret"}, {-1.0}}, j), MicroscopeRejection::kOutOfRange);
  EXPECT_EQ(read({{"objective_turret"}, {64.0}}, j), MicroscopeRejection::kOutOfRange);
  Message with_velocity({"focus_z"}, {0.0});
  with_velocity.velocities = {1.0};
  EXPECT_EQ(from_ros(with_velocity.build(), j), MicroscopeRejection::kBadSize);
  Message bad_stamp({"focus_z"}, {0.0});
  bad_stamp.build();
  bad_stamp.m.header_.stamp_.nanosec_ = 1'000'000'000u;
  EXPECT_EQ(from_ros(bad_stamp.m, j), MicroscopeRejection::kBadStamp);
  EXPECT_EQ(j.objective, 4);
  EXPECT_NE(std::string(to_string(MicroscopeRejection::kOutOfRange)).find("whole number"), std::string::npos);
}

// A slave end that keeps the commands it takes and reports `state`, both under `m`.
struct CollectingServer {
  std::mutex m;
  std::vector<MicroscopeJoints> taken;
  MicroscopeJoints state;
  MicroscopeServer server;
  CollectingServer(int domain, const MicroscopeJoints& initial)
      : state(initial),
        server(
            domain, {},
            [this](const MicroscopeJoints& j) {
              std::lock_guard lock(m);
              taken.push_back(j);
            },
            [this] {
              std::lock_guard lock(m);
              return state;
            }) {}
};

// The master's operator changes focus then objective: the slave end gets each change with both
// joints, its state comes back to the master, and nothing is sent before the operator asks.
TEST(MicroscopeLink, TheMastersChangesReachTheSlaveAndItsStateComesBack) {
  const int domain = test::test_domain_id();
  MicroscopeJoints start;
  start.has_focus = true;
  start.focus_z_m = 10e-6;
  start.objective = 1;
  CollectingServer slave(domain, start);
  std::mutex& m = slave.m;
  std::vector<MicroscopeJoints>& taken = slave.taken;
  MicroscopeJoints& slave_state = slave.state;
  MicroscopeServer& server = slave.server;
  MicroscopeJoints wanted = start;
  MicroscopeClient client(domain, {}, [&] {
    std::lock_guard lock(m);
    return wanted;
  });
  ASSERT_TRUE(test::wait_until([&] { return client.slave_state().has_value(); }, 20.0));
  EXPECT_EQ(client.slave_state()->objective, 1);
  EXPECT_EQ(client.slave_state()->focus_z_m, 10e-6);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(client.commands_sent(), 0u) << "a master that starts sends nothing";
  {
    std::lock_guard lock(m);
    EXPECT_TRUE(taken.empty());
    wanted.focus_z_m = 250e-6;
  }
  ASSERT_TRUE(test::wait_until([&] {
    std::lock_guard lock(m);
    return !taken.empty();
  }));
  {
    std::lock_guard lock(m);
    EXPECT_TRUE(taken.back().has_focus);
    EXPECT_EQ(taken.back().focus_z_m, 250e-6);
    EXPECT_EQ(taken.back().objective, 1) << "both joints: the latched command is the whole setting";
    wanted.objective = 4;
    slave_state.focus_z_m = 250e-6;
    slave_state.objective = 4;
  }
  ASSERT_TRUE(test::wait_until([&] {
    std::lock_guard lock(m);
    return taken.back().objective == 4;
  }));
  ASSERT_TRUE(test::wait_until([&] { return client.slave_state()->objective == 4; }));
  EXPECT_EQ(client.slave_state()->focus_z_m, 250e-6);
  EXPECT_EQ(client.commands_sent(), 2u);
  const MicroscopeServerStats st = server.stats();
  EXPECT_EQ(st.commands, 2u);
  EXPECT_GT(st.states, 1u);
}

// A master whose loop has not run yet knows no focus: the first one it knows is the start, not
// a change, so a master that starts sends nothing even when its drive does not start at 0.
TEST(MicroscopeLink, AMasterTakesTheFirstFocusItKnowsAsTheStart) {
  const int domain = test::test_domain_id();
  std::atomic<bool> known{false};
  std::atomic<int> taken{0};
  MicroscopeServer server(
      domain, {}, [&](const MicroscopeJoints&) { taken.fetch_add(1); }, [] { return MicroscopeJoints{}; });
  MicroscopeClient client(domain, {}, [&] {
    MicroscopeJoints j;
    if (!known.load()) return j;
    j.has_focus = true;
    j.focus_z_m = 120e-6;  // the configuration's focus_start_m
    j.objective = 0;
    return j;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  known = true;
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(client.commands_sent(), 0u);
  EXPECT_EQ(taken.load(), 0);
  EXPECT_EQ(server.stats().states, 0u) << "a slave that knows no state publishes none";
}

// A peer floods the command topic with garbage and good commands mixed: the server refuses the
// bad ones by reason, never hands them on, keeps publishing its state, and the last good command
// is the one that stays applied.
TEST(MicroscopeLink, AFloodOfGarbageIsRefusedAndTheLastGoodCommandStands) {
  const int domain = test::test_domain_id();
  MicroscopeJoints state;
  state.has_focus = true;
  state.objective = 0;
  CollectingServer slave(domain, state);
  std::mutex& m = slave.m;
  std::vector<MicroscopeJoints>& taken = slave.taken;
  MicroscopeServer& server = slave.server;
  Participant peer(domain);
  const dds_entity_t topic =
      dds_create_topic(peer.handle(), &sensor_msgs_msg_dds__JointState__desc,
                       std::string(kMicroscopeCommandDdsName).c_str(), nullptr, nullptr);
  ASSERT_GT(topic, 0);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  const dds_entity_t writer = dds_create_writer(peer.handle(), topic, qos, nullptr);
  dds_delete_qos(qos);
  ASSERT_GT(writer, 0);
  ASSERT_TRUE(test::wait_until([&] {
    dds_publication_matched_status_t st{};
    return dds_get_publication_matched_status(writer, &st) >= 0 && st.current_count > 0;
  }));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Kind {
    std::vector<const char*> names;
    std::vector<double> positions;
    MicroscopeRejection why;
  };
  const std::vector<Kind> kinds = {{{"focus_z"}, {nan}, MicroscopeRejection::kNonFinite},
                                   {{"focus_z"}, {1e308}, MicroscopeRejection::kOutOfRange},
                                   {{"objective_turret"}, {2.5}, MicroscopeRejection::kOutOfRange},
                                   {{"gripper_opening"}, {1e-3}, MicroscopeRejection::kUnknownJoint},
                                   {{}, {}, MicroscopeRejection::kBadSize},
                                   {{"focus_z", "focus_z"}, {0, 0}, MicroscopeRejection::kUnknownJoint},
                                   {{"focus_z"}, {50e-6}, MicroscopeRejection::kNone},
                                   {{"objective_turret"}, {1.0}, MicroscopeRejection::kNone}};
  // Paced: each bad kind is refused for its own reason. (A keep-last-1 writer may replace a sample
  // not yet delivered, so only a paced write is sure to arrive.)
  for (const Kind& k : kinds) {
    if (k.why == MicroscopeRejection::kNone) continue;
    const std::size_t why = static_cast<std::size_t>(k.why);
    const std::uint64_t before = server.stats().refused[why];
    Message msg(k.names, k.positions);
    dds_write(writer, &msg.build());
    EXPECT_TRUE(test::wait_until([&] { return server.stats().refused[why] > before; })) << to_string(k.why);
  }
  // Flooded: whatever of 800 mixed samples arrives, nothing bad is handed on.
  for (int i = 0; i < 800; ++i) {
    const Kind& k = kinds[static_cast<std::size_t>(i) % kinds.size()];
    Message msg(k.names, k.positions);
    dds_write(writer, &msg.build());
  }
  Message last({"focus_z", "objective_turret"}, {123e-6, 3.0});
  dds_write(writer, &last.build());
  ASSERT_TRUE(test::wait_until([&] {
    std::lock_guard lock(m);
    return !taken.empty() && taken.back().focus_z_m == 123e-6;
  }));
  {
    std::lock_guard lock(m);
    for (const MicroscopeJoints& j : taken) {
      EXPECT_TRUE(!j.has_focus || (std::isfinite(j.focus_z_m) && std::abs(j.focus_z_m) <= 1.0));
      EXPECT_TRUE(j.objective == -1 || j.objective == 1 || j.objective == 3) << j.objective;
    }
    EXPECT_EQ(taken.back().objective, 3);
  }
  const MicroscopeServerStats st = server.stats();
  const std::uint64_t states = st.states;
  EXPECT_TRUE(test::wait_until([&] { return server.stats().states > states; })) << "it still publishes";
}

// A slave that starts after the master's last change still takes it (transient local).
TEST(MicroscopeLink, ASlaveThatStartsLaterTakesTheLastCommand) {
  const int domain = test::test_domain_id();
  std::atomic<double> focus{0.0};
  MicroscopeClient client(domain, {}, [&] {
    MicroscopeJoints j;
    j.has_focus = true;
    j.focus_z_m = focus.load();
    j.objective = 0;
    return j;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  focus = 75e-6;
  ASSERT_TRUE(test::wait_until([&] { return client.commands_sent() == 1u; }));
  std::atomic<double> taken{-1.0};
  MicroscopeServer server(
      domain, {}, [&](const MicroscopeJoints& j) { taken = j.focus_z_m; }, [] { return MicroscopeJoints{}; });
  ASSERT_TRUE(test::wait_until([&] { return taken.load() >= 0.0; }, 20.0));
  EXPECT_EQ(taken.load(), 75e-6);
}

}  // namespace
}  // namespace mc::net

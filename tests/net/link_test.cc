#include "microcobot/net/link.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <thread>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/net/participant.h"
#include "microcobot/net/ros_mapping.h"
#include "net/net_test_support.h"
#include "support/counting_allocator.h"

namespace mc::net {
namespace {

using test::StatePublisher;
using test::test_domain_id;
using test::wait_until;

LinkConfig config(Role role) {
  LinkConfig c;
  c.domain_id = test_domain_id();
  c.role = role;
  return c;
}

NetSample target(double x, std::int64_t stamp) {
  NetSample s;
  s.channel = Channel::kTarget;
  s.stamp_ns = stamp;
  s.xyz = {x, 0.0, -1e-4};
  return s;
}

// Receives on `link` until a sample of channel `c` arrives (others are skipped).
bool receive_channel(Link& link, Channel c, NetSample& out, double timeout_s = 5.0) {
  return wait_until(
      [&] {
        NetSample s;
        while (link.receive(s)) {
          if (s.channel == c) {
            out = s;
            return true;
          }
        }
        return false;
      },
      timeout_s);
}

TEST(Link, MasterAndSlaveExchangeTargetsAndMeasuredPoses) {
  Link master(config(Role::kMaster));
  Link slave(config(Role::kSlave));
  ASSERT_TRUE(wait_until([&] { return master.peer_matched() && slave.peer_matched(); }));
  NetSample got;
  // Best effort: repeat until one arrives.
  ASSERT_TRUE(wait_until([&] {
    master.send(target(1e-3, 1000));
    return receive_channel(slave, Channel::kTarget, got, 0.01);
  }));
  EXPECT_EQ(got.stamp_ns, 1000);
  EXPECT_DOUBLE_EQ(got.xyz[0], 1e-3);
  EXPECT_DOUBLE_EQ(got.xyz[2], -1e-4);
  EXPECT_GT(got.received_ns, 0);

  NetSample pose = got;
  pose.channel = Channel::kMeasuredPose;
  ASSERT_TRUE(wait_until([&] {
    slave.send(pose);
    return receive_channel(master, Channel::kMeasuredPose, got, 0.01);
  }));
  EXPECT_DOUBLE_EQ(got.xyz[0], 1e-3);
  EXPECT_EQ(master.stats().rejected_total(), 0u);
  EXPECT_GT(master.stats().written, 0u);
}

TEST(Link, ALateSlaveStillGetsTheEstopReliableAndTransientLocal) {
  Link master(config(Role::kMaster));
  NetSample e;
  e.channel = Channel::kEstop;
  e.scalar = 1.0;
  ASSERT_TRUE(master.send(e));
  // Written before any slave exists: the writer keeps it for late joiners.
  ASSERT_TRUE(wait_until([&] { return master.stats().written == 1; }));
  Link slave(config(Role::kSlave));
  NetSample got;
  ASSERT_TRUE(receive_channel(slave, Channel::kEstop, got, 10.0));
  EXPECT_EQ(got.scalar, 1.0);
}

TEST(Link, SendingOnAChannelThePeerPublishesIsCountedAndDropped) {
  Link slave(config(Role::kSlave));
  ASSERT_TRUE(slave.send(target(0.0, 1)));  // targets are the master's
  ASSERT_TRUE(wait_until([&] { return slave.stats().not_published == 1; }));
  EXPECT_EQ(slave.stats().written, 0u);
}

TEST(Link, MalformedSamplesFromTheNetworkAreCountedAndNeverReachTheLoop) {
  Link slave(config(Role::kSlave));
  // A hostile or broken master: raw DDS on the same topics.
  Participant rogue(test_domain_id());
  auto make_writer = [&](Channel c) {
    const TopicSpec& spec = topic(c);
    dds_qos_t* qos = make_qos(spec);
    const dds_entity_t t = dds_create_topic(rogue.handle(), descriptor(spec.type),
                                            std::string(spec.dds_name).c_str(), qos, nullptr);
    const dds_entity_t w = dds_create_writer(rogue.handle(), t, qos, nullptr);
    dds_delete_qos(qos);
    return w;
  };
  const dds_entity_t pose_writer = make_writer(Channel::kTarget);
  const dds_entity_t joint_writer = make_writer(Channel::kGripperTarget);
  ASSERT_GT(pose_writer, 0);
  ASSERT_GT(joint_writer, 0);
  ASSERT_TRUE(wait_until([&] {
    dds_publication_matched_status_t m{};
    dds_get_publication_matched_status(pose_writer, &m);
    dds_publication_matched_status_t j{};
    dds_get_publication_matched_status(joint_writer, &j);
    return m.current_count > 0 && j.current_count > 0;
  }));

  geometry_msgs_msg_dds__PoseStamped_ bad;
  to_ros(target(0.0, 5), bad);
  bad.pose_.position_.x_ = std::numeric_limits<double>::quiet_NaN();
  sensor_msgs_msg_dds__JointState_ js;
  JointStateBuffer buf;
  NetSample opening;
  to_ros(opening, buf, js);
  js.position_._length = 0;  // a JointState without its position
  ASSERT_TRUE(wait_until([&] {
    dds_write(pose_writer, &bad);
    dds_write(joint_writer, &js);
    const LinkStats s = slave.stats();
    return s.rejected[static_cast<std::size_t>(Rejection::kNonFinite)] > 0 &&
           s.rejected[static_cast<std::size_t>(Rejection::kBadSize)] > 0;
  }));
  bad.pose_.position_.x_ = 3.0;  // 3 m: out of range
  ASSERT_TRUE(wait_until([&] {
    dds_write(pose_writer, &bad);
    return slave.stats().rejected[static_cast<std::size_t>(Rejection::kOutOfRange)] > 0;
  }));
  NetSample s;
  EXPECT_FALSE(slave.receive(s));
  EXPECT_EQ(slave.stats().received, 0u);
  dds_delete(pose_writer);
  dds_delete(joint_writer);
}

TEST(Link, TheLoopSideNeverAllocates) {
  Link master(config(Role::kMaster));
  Link slave(config(Role::kSlave));
  ASSERT_TRUE(wait_until([&] { return master.peer_matched() && slave.peer_matched(); }));
  std::size_t allocations = 0;
  {
    mc::test::AllocationGuard guard(std::this_thread::get_id());
    NetSample s;
    for (int i = 0; i < 200; ++i) {
      master.send(target(1e-4 * i, 10 + i));
      while (slave.receive(s)) {
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_GT(slave.stats().received, 0u);
}

// The watchdogs' DDS verdict (deadline and liveliness feed them).
TEST(Link, APeerIsAliveWhileItsStateFlowsAndNotOnceItFallsSilentOrLeaves) {
  Link master(config(Role::kMaster));
  auto slave = std::make_unique<Link>(config(Role::kSlave));
  StatePublisher from_master(master);
  auto from_slave = std::make_unique<StatePublisher>(*slave);
  ASSERT_TRUE(wait_until([&] { return master.peer_alive() && slave->peer_alive(); }, 20.0))
      << "matched " << master.peer_matched() << slave->peer_matched();

  // Silent but present: the requested deadline (10 ms) is missed, then the state flows again.
  from_slave->on = false;
  const auto silent = std::chrono::steady_clock::now();
  ASSERT_TRUE(wait_until([&] { return !master.peer_alive(); }, 5.0))
      << "deadlines missed " << master.stats().deadline_missed << ", liveliness lost "
      << master.stats().liveliness_lost << ", received " << master.stats().received << ", rejected "
      << master.stats().rejected_total() << ", slave wrote " << slave->stats().written << " failed "
      << slave->stats().write_failed;
  const double noticed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - silent).count();
  std::printf("silent slave noticed after %.1f ms (deadline %.0f ms)\n", 1e3 * noticed_s,
              1e3 * kStateDeadline_s);
  EXPECT_GT(master.stats().deadline_missed, 0u);
  EXPECT_TRUE(master.peer_matched());  // still there
  from_slave->on = true;
  EXPECT_TRUE(wait_until([&] { return master.peer_alive(); }, 5.0));

  // Gone: its writers leave with it.
  from_slave.reset();
  slave.reset();
  EXPECT_TRUE(wait_until([&] { return !master.peer_alive() && !master.peer_matched(); }, 5.0));
}

TEST(Link, RefusesADomainIdOutsideTheRange) {
  LinkConfig c;
  c.domain_id = 231;
  EXPECT_THROW(Link{c}, InvalidParams);
  c.domain_id = -1;
  EXPECT_THROW(Link{c}, InvalidParams);
  c.domain_id = test_domain_id();
  c.poll_period_s = 0.0;
  EXPECT_THROW(Link{c}, InvalidParams);
}

TEST(Link, ADomainWhosePortAnotherProgramHoldsFailsWithOneLineNamingThePort) {
  // Cyclone's port mapping: the discovery multicast port of domain d is 7400 + 250 d. A socket
  // bound there without SO_REUSEADDR (what a program given that port by the kernel holds) keeps
  // Cyclone from creating the domain.
  const int domain = test_domain_id();
  const int port = 7400 + 250 * domain;
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_ANY);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    GTEST_SKIP() << "port " << port << " is already taken on this machine";
  }
  LinkConfig c;
  c.domain_id = domain;
  c.role = Role::kSlave;
  try {
    Link link(c);
    ADD_FAILURE() << "the domain was created while port " << port << " was held";
  } catch (const ComputationFailed& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cannot create domain " + std::to_string(domain)), std::string::npos) << what;
    EXPECT_NE(what.find(std::to_string(port) + ": address in use"), std::string::npos) << what;
    EXPECT_NE(what.find("another program holds the port"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  ::close(fd);
}

}  // namespace
}  // namespace mc::net

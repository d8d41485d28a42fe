// Where the link's DDS traffic goes (net/cyclone_config.h): loopback by default (with multicast
// participant discovery there, for ROS 2 nodes with ROS_LOCALHOST_ONLY=1), one named interface and
// unicast peers for two machines, nothing that could alter the XML.
#include "microcobot/net/cyclone_config.h"

#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/net/participant.h"
#include "net/net_test_support.h"

namespace mc::net {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

TEST(CycloneConfig, DefaultsToLoopbackWithMulticastForParticipantDiscoveryOnly) {
  const std::string xml = cyclone_config(NetworkConfig{});
  // multicast="true": lo's MULTICAST flag is off on a stock Linux, yet the kernel delivers
  // multicast on lo; "spdp": only participant discovery, endpoints and data stay unicast.
  EXPECT_THAT(xml, HasSubstr(R"(<NetworkInterface address="127.0.0.1" multicast="true"/>)"));
  EXPECT_THAT(xml, HasSubstr("<AllowMulticast>spdp</AllowMulticast>"));
  // The unicast peers as before: the platform's own processes and a ROS 2 node whose Cyclone fell
  // back to unicast (lo without the flag) meet by them.
  EXPECT_THAT(xml, HasSubstr(R"(<Peers><Peer address="127.0.0.1"/></Peers>)"));
  EXPECT_THAT(xml, HasSubstr("<ParticipantIndex>auto</ParticipantIndex>"));
  EXPECT_TRUE(on_loopback(NetworkConfig{}));
}

TEST(CycloneConfig, LoopbackIsLoOr127Slash8OrIpv6Loopback) {
  NetworkConfig n;
  for (const char* i : {"127.0.0.1", "127.0.1.1", "::1", "lo"}) {
    n.interface = i;
    EXPECT_TRUE(on_loopback(n)) << i;
    EXPECT_THAT(cyclone_config(n), HasSubstr("<AllowMulticast>spdp</AllowMulticast>")) << i;
  }
  for (const char* i : {"eth0", "lo0", "10.0.0.7", "fe80::1", "127-host", "198.18.0.1"}) {
    n.interface = i;
    EXPECT_FALSE(on_loopback(n)) << i;
    EXPECT_THAT(cyclone_config(n), HasSubstr("<AllowMulticast>false</AllowMulticast>")) << i;
    EXPECT_THAT(cyclone_config(n), Not(HasSubstr("multicast=\"true\""))) << i;
  }
}

TEST(CycloneConfig, TwoMachinesNameTheirInterfaceAndTheirPeers) {
  NetworkConfig n;
  n.interface = "eth0";
  n.peers = {"192.168.10.2", "fe80::1%eth0", "slave-bench.local"};
  const std::string xml = cyclone_config(n);
  EXPECT_THAT(xml, HasSubstr(R"(<NetworkInterface name="eth0"/>)")) << "a name, not an address";
  // Off loopback no multicast at all: discovery reaches the peers named, nothing else.
  EXPECT_THAT(xml, HasSubstr("<AllowMulticast>false</AllowMulticast>"));
  EXPECT_THAT(xml, HasSubstr(R"(<Peer address="192.168.10.2"/><Peer address="fe80::1%eth0"/>)"));
  EXPECT_THAT(xml, HasSubstr(R"(<Peer address="slave-bench.local"/>)"));
  n.interface = "10.0.0.7";
  EXPECT_THAT(cyclone_config(n), HasSubstr(R"(<NetworkInterface address="10.0.0.7"/>)"));
  n.interface = "fe80::2";
  EXPECT_THAT(cyclone_config(n), HasSubstr(R"(<NetworkInterface address="fe80::2"/>)"));
}

TEST(CycloneConfig, RefusesValuesThatAreNotAddressesHostsOrNames) {
  const auto refused = [](const NetworkConfig& n, const std::string& field) {
    try {
      cyclone_config(n);
      ADD_FAILURE() << "accepted";
    } catch (const InvalidParams& e) {
      EXPECT_EQ(e.field(), field) << e.what();
      EXPECT_THAT(std::string(e.what()), Not(HasSubstr("\n")));
    }
  };
  NetworkConfig n;
  n.interface = R"(eth0"/><Peer address="evil)";
  refused(n, "network.interface");
  n.interface = "";
  refused(n, "network.interface");
  n.interface = std::string(254, 'a');
  refused(n, "network.interface");
  n = NetworkConfig{};
  n.peers = {};
  refused(n, "network.peers");
  n.peers = {"127.0.0.1", "a b"};
  refused(n, "network.peers[1]");
  n.peers = std::vector<std::string>(17, "127.0.0.1");
  refused(n, "network.peers");
}

TEST(CycloneConfig, ADomainKeepsTheNetworkItWasOpenedWith) {
  const int domain = test::test_domain_id();
  const Participant first(domain);
  NetworkConfig other;
  other.peers = {"127.0.0.1", "127.0.0.2"};
  EXPECT_THROW(Participant(domain, other), InvalidParams);
  const Participant same(domain, NetworkConfig{});  // the same configuration joins the domain
  EXPECT_EQ(same.domain_id(), domain);
}

}  // namespace
}  // namespace mc::net

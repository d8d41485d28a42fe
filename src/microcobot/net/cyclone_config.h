#pragma once
/// @file
/// The Cyclone DDS configuration of the link: one local interface, unicast discovery towards a
/// list of peers (participant indices picked automatically), data by unicast. The default is
/// loopback (interface and peer 127.0.0.1): tests and two processes on one machine never reach
/// outside it, and parallel runs are kept apart by their domain ids. On loopback, participant
/// discovery (SPDP) also goes by multicast, so that a ROS 2 node on the same machine with
/// ROS_LOCALHOST_ONLY=1 finds the platform without further configuration. Two machines name their
/// own interface and the other machine as peer, without multicast (docs/distributed.md).

#include <string>
#include <vector>

namespace mc::net {

/// Highest domain id the link accepts: Cyclone's default port mapping (7400 + 250 * domain +
/// offsets) stays below 65536 up to 232; a margin of two.
inline constexpr int kMaxDomainId = 230;

/// Highest domain id whose ports (7400 + 250 x domain + 10 + 2 x participant index + 1, indices
/// up to 20) all lie below Linux's default ephemeral range (32768 and up). Above it, a socket any
/// program bound to port 0 may hold the domain's discovery port, and the domain cannot be created.
inline constexpr int kMaxPortableDomainId = 101;
static_assert(7400 + 250 * kMaxPortableDomainId + 10 + 2 * 20 + 1 < 32768);

/// Where the link's traffic goes.
struct NetworkConfig {
  /// The local interface DDS uses: an IPv4/IPv6 address of this machine or an interface name
  /// (e.g. eth0).
  std::string interface = "127.0.0.1";
  /// Addresses (or host names) discovery contacts by unicast: the other end's machine; 1 to 16.
  std::vector<std::string> peers = {"127.0.0.1"};
  /// Throws InvalidParams naming `network.interface` or `network.peers[i]`: empty, longer than 253
  /// characters, or a character outside letters, digits and . : - _ % (an address, a host or an
  /// interface name; nothing that could alter the XML it goes into).
  void validate() const;
  bool operator==(const NetworkConfig&) const = default;
};

/// Whether `network` keeps to this machine's loopback: its interface is `lo`, ::1 or an address in
/// 127.0.0.0/8 (the peers then can only be reached through loopback too).
bool on_loopback(const NetworkConfig& network);

/// "loopback" or "interface ADDR, peers A, B": where the traffic goes, for startup banners.
std::string describe(const NetworkConfig& network);

/// The XML fragment given to dds_create_domain (Cyclone DDS 0.10 configuration elements:
/// General/Interfaces/NetworkInterface (address= for an address, name= for a name; on loopback
/// multicast="true"), General/AllowMulticast (spdp on loopback, false elsewhere),
/// Discovery/ParticipantIndex, Discovery/Peers, Discovery/MaxAutoParticipantIndex). Validates
/// `network` first.
std::string cyclone_config(const NetworkConfig& network);

}  // namespace mc::net

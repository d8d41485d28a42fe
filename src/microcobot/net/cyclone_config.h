#pragma once
/// @file
/// The Cyclone DDS configuration of the link: one local interface, no multicast, unicast
/// discovery towards a list of peers (participant indices picked automatically). The default is
/// loopback (interface and peer 127.0.0.1): tests and two processes on one machine never reach
/// outside it, and parallel runs are kept apart by their domain ids. Two machines name their own
/// interface and the other machine as peer (docs/distributed.md).

#include <string>
#include <vector>

namespace mc::net {

/// Highest domain id the link accepts: Cyclone's default port mapping (7400 + 250 * domain +
/// offsets) stays below 65536 up to 232; a margin of two.
inline constexpr int kMaxDomainId = 230;

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

/// The XML fragment given to dds_create_domain (Cyclone DDS 0.10 configuration elements:
/// General/Interfaces/NetworkInterface (address= for an address, name= for a name),
/// General/AllowMulticast, Discovery/ParticipantIndex, Discovery/Peers,
/// Discovery/MaxAutoParticipantIndex). Validates `network` first.
std::string cyclone_config(const NetworkConfig& network);

}  // namespace mc::net

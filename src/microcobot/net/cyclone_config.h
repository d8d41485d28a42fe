#pragma once
/// @file
/// The Cyclone DDS configuration of the link: loopback only, no multicast, unicast discovery
/// towards 127.0.0.1 (participant indices picked automatically). Tests and two processes on one
/// machine therefore never reach outside it, and parallel runs are kept apart by their domain ids.

#include <string>

namespace mc::net {

/// Highest domain id the link accepts: Cyclone's default port mapping (7400 + 250 * domain +
/// offsets) stays below 65536 up to 232; a margin of two.
inline constexpr int kMaxDomainId = 230;

/// The XML fragment given to dds_create_domain (Cyclone DDS 0.10 configuration elements:
/// General/Interfaces/NetworkInterface, General/AllowMulticast, Discovery/ParticipantIndex,
/// Discovery/Peers, Discovery/MaxAutoParticipantIndex).
std::string loopback_config();

}  // namespace mc::net

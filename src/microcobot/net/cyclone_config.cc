#include "microcobot/net/cyclone_config.h"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"

namespace mc::net {

namespace {

void check_host(const std::string& value, const std::string& field) {
  if (value.empty() || value.size() > 253) throw InvalidParams(field, "must hold 1 to 253 characters");
  const bool clean = std::all_of(value.begin(), value.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == ':' || c == '-' || c == '_' ||
           c == '%';
  });
  if (!clean) {
    throw InvalidParams(
        field,
        "'" + excerpt(value) + "' is not an address, host or interface name (letters, digits, . : - _ %)");
  }
}

/// An IPv4 or IPv6 literal (digits, hex digits, dots, colons), as opposed to an interface name.
bool is_address(const std::string& value) {
  const bool chars = std::all_of(value.begin(), value.end(), [](char c) {
    return std::isxdigit(static_cast<unsigned char>(c)) || c == '.' || c == ':';
  });
  return chars && (value.find('.') != std::string::npos || value.find(':') != std::string::npos);
}

}  // namespace

void NetworkConfig::validate() const {
  check_host(interface, "network.interface");
  if (peers.empty() || peers.size() > 16) {
    throw InvalidParams("network.peers", "must list 1 to 16 peers", static_cast<double>(peers.size()));
  }
  for (std::size_t i = 0; i < peers.size(); ++i)
    check_host(peers[i], "network.peers[" + std::to_string(i) + "]");
}

bool on_loopback(const NetworkConfig& network) {
  const std::string& i = network.interface;
  return i == "lo" || i == "::1" || (is_address(i) && i.rfind("127.", 0) == 0);
}

std::string cyclone_config(const NetworkConfig& network) {
  network.validate();
  const bool loopback = on_loopback(network);
  std::string xml = "<General><Interfaces><NetworkInterface ";
  xml += is_address(network.interface) ? "address" : "name";
  xml += "=\"" + network.interface + "\"";
  // On loopback, discovery also goes by multicast (SPDP only: endpoints and data stay unicast),
  // because that is all a ROS 2 node with ROS_LOCALHOST_ONLY=1 (Humble's rmw_cyclonedds: interface
  // 127.0.0.1, Cyclone's defaults otherwise) sends once `lo` has the MULTICAST flag, and it then
  // listens on random unicast ports the peers below cannot reach. multicast="true": Linux delivers
  // multicast on lo whether or not the flag is set, and Cyclone, which reads the flag, would
  // otherwise switch multicast off with a warning on every start. Off loopback multicast stays off:
  // a lab network is reached only through the peers named (docs/distributed.md).
  if (loopback) xml += " multicast=\"true\"";
  xml += "/></Interfaces><AllowMulticast>";
  xml += loopback ? "spdp" : "false";
  xml += "</AllowMulticast></General>";
  // Unicast discovery goes to the peers' participant indices 0..Max: a handful of processes per
  // domain and machine is what the link needs.
  xml +=
      "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
      "<MaxAutoParticipantIndex>20</MaxAutoParticipantIndex><Peers>";
  for (const auto& p : network.peers) xml += "<Peer address=\"" + p + "\"/>";
  xml += "</Peers></Discovery>";
  return xml;
}

std::string describe(const NetworkConfig& network) {
  if (network == NetworkConfig{}) return "loopback";
  return fmt::format("interface {}, peers {}", network.interface, fmt::join(network.peers, ", "));
}

}  // namespace mc::net

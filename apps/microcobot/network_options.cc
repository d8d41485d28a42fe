#include "network_options.h"

#include "microcobot/core/error.h"

namespace mc::cli {

void add_network_options(CLI::App& cmd, NetworkOptions& opts) {
  cmd.add_option("--interface", opts.interface,
                 "Local network interface of the DDS link: an address of this machine or an interface name "
                 "(default 127.0.0.1: this machine only)");
  cmd.add_option(
      "--peer", opts.peers,
      "Address of the other end's machine, for discovery by unicast (repeatable; default 127.0.0.1)");
}

net::NetworkConfig network_config(const NetworkOptions& opts) {
  net::NetworkConfig n;
  n.interface = opts.interface;
  if (!opts.peers.empty()) n.peers = opts.peers;
  try {
    n.validate();
  } catch (const InvalidParams& e) {
    // "invalid parameter network.peers[1]: ...": the flag's name instead of the field's.
    const std::string what = e.what();
    const std::string prefix = "invalid parameter " + e.field() + ": ";
    const std::string reason = what.rfind(prefix, 0) == 0 ? what.substr(prefix.size()) : what;
    throw UsageError((e.field().rfind("network.peers", 0) == 0 ? "--peer: " : "--interface: ") + reason);
  }
  return n;
}

}  // namespace mc::cli

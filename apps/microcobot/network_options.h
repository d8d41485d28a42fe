#pragma once
/// @file
/// `--interface` and `--peer`: where a DDS link's traffic goes (net::NetworkConfig), shared by
/// `serve --role master|slave` and `link echo|ping`. Default: loopback.

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "microcobot/net/cyclone_config.h"

namespace mc::cli {

struct NetworkOptions {
  std::string interface = "127.0.0.1";
  std::vector<std::string> peers;  ///< empty: 127.0.0.1
  /// Whether a flag moved it off loopback (commands that have no link refuse the flags).
  bool given() const { return interface != "127.0.0.1" || !peers.empty(); }
};

/// Adds `--interface ADDR|NAME` and `--peer ADDR` (repeatable) to `cmd`.
void add_network_options(CLI::App& cmd, NetworkOptions& opts);

/// The configuration the flags describe. Throws UsageError naming the flag when a value is not an
/// address, host or interface name (exit 2).
net::NetworkConfig network_config(const NetworkOptions& opts);

}  // namespace mc::cli

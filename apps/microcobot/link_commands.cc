// `microcobot link`: the DDS link between a master and a slave process on its own
// (src/microcobot/net, docs/distributed.md). `link echo` is a slave that returns every target as
// its measured position; `link ping` is a master that publishes targets at a fixed rate and
// measures the round trips through the echo. Both use Cyclone DDS restricted to loopback.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/error.h"
#include "microcobot/net/cyclone_config.h"
#include "microcobot/net/link.h"
#include "network_options.h"
#include "signals.h"

namespace link_commands {
namespace {

namespace net = mc::net;
using mc::cli::CommonOptions;
using Clock = std::chrono::steady_clock;

std::int64_t ns_since_epoch(Clock::time_point t) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
}

std::int64_t ros_time_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

nlohmann::json rejected_json(const net::LinkStats& s) {
  return {{"non_finite", s.rejected[static_cast<std::size_t>(net::Rejection::kNonFinite)]},
          {"out_of_range", s.rejected[static_cast<std::size_t>(net::Rejection::kOutOfRange)]},
          {"bad_stamp", s.rejected[static_cast<std::size_t>(net::Rejection::kBadStamp)]},
          {"bad_size", s.rejected[static_cast<std::size_t>(net::Rejection::kBadSize)]}};
}

void add_domain_option(CLI::App& cmd, int& domain) {
  cmd.add_option(
         "--domain", domain,
         fmt::format("DDS domain id, 0 to {} (default 0; the peer must use the same)", net::kMaxDomainId))
      ->check(CLI::Range(0, net::kMaxDomainId));
}

// ---- echo -------------------------------------------------------------------------------------

struct EchoOptions {
  CommonOptions common;
  int domain = 0;
  mc::cli::NetworkOptions network;
  double duration_s = 0.0;
};

void run_echo(const EchoOptions& o) {
  net::LinkConfig config;
  config.domain_id = o.domain;
  config.role = net::Role::kSlave;
  config.network = mc::cli::network_config(o.network);
  mc::cli::set_cooperative_interrupts(true);
  net::Link link(config);
  std::cerr << fmt::format("link echo: slave on DDS domain {} ({}); SIGINT/SIGTERM stops\n", o.domain,
                           mc::net::describe(config.network));
  std::uint64_t echoed = 0, estops = 0;
  bool estop = false;
  const auto start = Clock::now();
  while (mc::cli::interrupt_signal() == 0) {
    net::NetSample s;
    while (link.receive(s)) {
      net::NetSample back = s;
      back.received_ns = 0;
      switch (s.channel) {
        case net::Channel::kTarget:
          back.channel = net::Channel::kMeasuredPose;
          echoed += link.send(back) ? 1 : 0;
          break;
        case net::Channel::kGripperTarget:
          back.channel = net::Channel::kGripperOpening;
          echoed += link.send(back) ? 1 : 0;
          break;
        case net::Channel::kEstop:
          estop = s.scalar != 0.0;
          ++estops;
          break;
        default:
          break;
      }
    }
    if (o.duration_s > 0 && std::chrono::duration<double>(Clock::now() - start).count() >= o.duration_s)
      break;
    // The haptic loop's period: an echo adds at most 0.1 ms to the round trip.
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  mc::cli::set_cooperative_interrupts(false);
  const int sig = mc::cli::interrupt_signal();
  const net::LinkStats st = link.stats();
  const nlohmann::json summary = {{"domain", o.domain},
                                  {"role", "slave"},
                                  {"received", st.received},
                                  {"echoed", echoed},
                                  {"estop_received", estops > 0},
                                  {"estop", estop},
                                  {"rejected", st.rejected_total()},
                                  {"rejected_by_reason", rejected_json(st)},
                                  {"receive_dropped", st.receive_dropped},
                                  {"deadline_missed", st.deadline_missed},
                                  {"liveliness_lost", st.liveliness_lost},
                                  {"stopped_by", sig ? mc::cli::signal_name(sig) : "duration"}};
  mc::cli::emit(
      o.common, summary,
      fmt::format("link echo: {} samples received, {} echoed, {} refused; e-stop {}; stopped by {}\n",
                  st.received, echoed, st.rejected_total(),
                  estops > 0 ? (estop ? "received (engaged)" : "received (released)") : "not received",
                  sig ? mc::cli::signal_name(sig) : "duration"));
}

// ---- ping -------------------------------------------------------------------------------------

struct PingOptions {
  CommonOptions common;
  int domain = 0;
  mc::cli::NetworkOptions network;
  int count = 1000;
  double rate_Hz = 1000.0;
  double wait_s = 10.0;
  bool estop = false;
  bool gripper = false;
};

double percentile(const std::vector<double>& sorted, double p) {
  const auto n = sorted.size();
  const auto k = static_cast<std::size_t>(std::ceil(p * static_cast<double>(n)));
  return sorted[std::min(n - 1, k == 0 ? 0 : k - 1)];
}

void run_ping(const PingOptions& o) {
  net::LinkConfig config;
  config.domain_id = o.domain;
  config.role = net::Role::kMaster;
  config.network = mc::cli::network_config(o.network);
  config.ring_capacity = 1024;
  net::Link link(config);

  // Discovery: both directions of every state topic matched, or no peer.
  const auto discovery_end = Clock::now() + std::chrono::duration<double>(o.wait_s);
  while (!link.peer_matched()) {
    if (Clock::now() >= discovery_end)
      throw mc::ComputationFailed(fmt::format(
          "no peer on DDS domain {} within {:g} s (start `microcobot link echo --domain {}` first)", o.domain,
          o.wait_s, o.domain));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }

  const auto n = static_cast<std::size_t>(o.count);
  std::vector<std::int64_t> stamps(n), sent_ns(n);
  std::vector<bool> back(n, false);
  std::vector<double> rtt;
  rtt.reserve(n);
  std::uint64_t unexpected = 0;
  std::size_t sent = 0;
  auto drain = [&] {
    net::NetSample s;
    while (link.receive(s)) {
      if (s.channel != net::Channel::kMeasuredPose) continue;
      const auto it =
          std::lower_bound(stamps.begin(), stamps.begin() + static_cast<std::ptrdiff_t>(sent), s.stamp_ns);
      const auto i = static_cast<std::size_t>(it - stamps.begin());
      if (i >= sent || *it != s.stamp_ns || back[i]) {
        ++unexpected;
        continue;
      }
      back[i] = true;
      rtt.push_back(static_cast<double>(s.received_ns - sent_ns[i]) * 1e-9);
    }
  };

  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / o.rate_Hz));
  const auto t0 = Clock::now();
  std::int64_t last_stamp = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto due = t0 + static_cast<Clock::rep>(i) * period;
    while (Clock::now() < due) {
      drain();
      std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
    // A 1 mm circle in x-y: distinct, plausible targets (stamps identify them: strictly increasing).
    // Target i is (1 mm cos(2 pi i / 1000), 1 mm sin(2 pi i / 1000), 0): a fixed pattern that a
    // subscriber checks value by value (tests/net/wire).
    const double phase = 2.0 * M_PI * static_cast<double>(i) / 1000.0;
    net::NetSample s;
    s.channel = net::Channel::kTarget;
    s.stamp_ns = std::max(ros_time_ns(), last_stamp + 1);
    last_stamp = s.stamp_ns;
    s.xyz = {1e-3 * std::cos(phase), 1e-3 * std::sin(phase), 0.0};
    stamps[i] = s.stamp_ns;
    sent_ns[i] = ns_since_epoch(Clock::now());
    sent = i + 1;
    link.send(s);
    if (o.gripper) {
      // Gripper target i: an opening of 5 mm + 2 mm sin(2 pi i / 1000), with the target's stamp.
      net::NetSample g;
      g.channel = net::Channel::kGripperTarget;
      g.stamp_ns = s.stamp_ns;
      g.scalar = 5e-3 + 2e-3 * std::sin(phase);
      link.send(g);
    }
  }
  // Late echoes: wait up to 0.5 s for the rest.
  const auto tail_end = Clock::now() + std::chrono::milliseconds(500);
  while (rtt.size() < n && Clock::now() < tail_end) {
    drain();
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  const double duration_s = std::chrono::duration<double>(Clock::now() - t0).count();
  bool estop_acked = false;
  if (o.estop) {
    net::NetSample s;
    s.channel = net::Channel::kEstop;
    s.stamp_ns = ros_time_ns();
    s.scalar = 1.0;
    link.send(s);
    estop_acked = link.flush(2.0);
  }
  if (rtt.empty())
    throw mc::ComputationFailed(
        fmt::format("no echo came back on DDS domain {} ({} targets sent)", o.domain, n));
  std::sort(rtt.begin(), rtt.end());
  const net::LinkStats st = link.stats();
  const std::size_t lost = n - rtt.size();
  const nlohmann::json summary = {{"domain", o.domain},
                                  {"rate_Hz", o.rate_Hz},
                                  {"sent", n},
                                  {"received", rtt.size()},
                                  {"lost", lost},
                                  {"loss", static_cast<double>(lost) / static_cast<double>(n)},
                                  {"rtt_p50_s", percentile(rtt, 0.5)},
                                  {"rtt_p99_s", percentile(rtt, 0.99)},
                                  {"rtt_max_s", rtt.back()},
                                  {"unexpected", unexpected},
                                  {"rejected", st.rejected_total()},
                                  {"rejected_by_reason", rejected_json(st)},
                                  {"send_dropped", st.send_dropped},
                                  {"duration_s", duration_s},
                                  {"gripper_sent", o.gripper},
                                  {"estop_sent", o.estop},
                                  {"estop_acknowledged", estop_acked}};
  mc::cli::emit(
      o.common, summary,
      fmt::format("link ping: {} of {} echoes back ({} lost), round trip p50 {:.3f} ms, p99 {:.3f} ms, "
                  "max {:.3f} ms{}\n",
                  rtt.size(), n, lost, 1e3 * percentile(rtt, 0.5), 1e3 * percentile(rtt, 0.99),
                  1e3 * rtt.back(),
                  o.estop ? (estop_acked ? "; e-stop acknowledged" : "; e-stop NOT acknowledged") : ""));
}

void add_link(CLI::App& group) {
  auto* echo = group.add_subcommand(
      "echo", "Slave end: return every target as the measured position (until SIGINT/SIGTERM or --duration)");
  auto eo = std::make_shared<EchoOptions>();
  add_domain_option(*echo, eo->domain);
  mc::cli::add_network_options(*echo, eo->network);
  echo->add_flag("--json", eo->common.json, "Print a machine-readable JSON summary on stdout when stopped");
  echo->add_option("--duration", eo->duration_s, "Stop after this many seconds (default: on a signal only)")
      ->check(mc::cli::Range(0.0, 1e7));
  echo->callback([eo] { run_echo(*eo); });

  auto* ping = group.add_subcommand(
      "ping", "Master end: publish targets at a fixed rate to `link echo` and measure the round trips");
  auto po = std::make_shared<PingOptions>();
  add_domain_option(*ping, po->domain);
  mc::cli::add_network_options(*ping, po->network);
  ping->add_flag("--json", po->common.json, "Print a machine-readable JSON summary on stdout");
  ping->add_option("--count", po->count, "Targets to publish (default 1000)")->check(CLI::Range(1, 10000000));
  ping->add_option("--rate", po->rate_Hz, "Publishing rate in Hz (default 1000)")
      ->check(mc::cli::Range(1.0, 10000.0));
  ping->add_option("--wait", po->wait_s, "Seconds to wait for the peer's discovery (default 10)")
      ->check(mc::cli::Range(0.1, 600.0));
  ping->add_flag(
      "--estop", po->estop,
      "Publish the e-stop (reliable, transient-local) at the end and wait for its acknowledgement");
  ping->add_flag("--gripper", po->gripper,
                 "Also publish a gripper target (opening 5 mm + 2 mm sin(2 pi i / 1000)) with each target");
  ping->callback([po] { run_ping(*po); });
}

const bool kRegistered = mc::cli::register_group(
    {"link", "The DDS link between a master and a slave process (Cyclone DDS, ROS 2 topics; loopback)", 7,
     &add_link});

}  // namespace
}  // namespace link_commands

#pragma once
/// @file
/// The microscope's topics (microscope_topics.h) served and used, each end in a thread of its own
/// (never the loop), on a participant of its own:
///
///   MicroscopeServer   the slave process: takes the commands any peer publishes (the master,
///                      a ROS 2 node) and hands each to `on_command` (the live platform's ring,
///                      applied at the next operator tick); publishes the drive's state at 10 Hz
///                      and at most every 20 ms while it changes
///   MicroscopeClient   the master process: publishes what its operator changes (the focus
///                      target, the objective), polled every 20 ms, and keeps the slave's state
///
/// The master sends only changes, so that a master that starts does not move a microscope
/// another node has set. Commands are latched (transient local): a slave that starts (or
/// restarts) after the master's last change still takes it.

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include <dds/dds.h>

#include "microcobot/net/microscope_topics.h"
#include "microcobot/net/participant.h"

namespace mc::net {

struct MicroscopeServerStats {
  std::uint64_t commands = 0;  ///< accepted and handed on
  std::array<std::uint64_t, kMicroscopeRejectionCount> refused{};
  std::uint64_t states = 0;  ///< published
};

class MicroscopeServer {
 public:
  using OnCommand = std::function<void(const MicroscopeJoints&)>;
  using ReadState = std::function<MicroscopeJoints()>;  ///< neither joint: not known yet (nothing published)
  /// Both callbacks run on this object's thread. Throws InvalidParams / ComputationFailed as
  /// Participant does.
  MicroscopeServer(int domain_id, const NetworkConfig& network, OnCommand on_command, ReadState read_state);
  ~MicroscopeServer();
  MicroscopeServer(const MicroscopeServer&) = delete;
  MicroscopeServer& operator=(const MicroscopeServer&) = delete;

  MicroscopeServerStats stats() const;

 private:
  void run();
  void take_commands();
  void publish(const MicroscopeJoints& state);

  Participant participant_;
  OnCommand on_command_;
  ReadState read_state_;
  dds_entity_t command_reader_ = 0, state_writer_ = 0, waitset_ = 0;
  std::atomic<std::uint64_t> commands_{0}, states_{0};
  std::array<std::atomic<std::uint64_t>, kMicroscopeRejectionCount> refused_{};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

class MicroscopeClient {
 public:
  /// What this end's operator wants (focus target and objective); polled on this object's thread.
  /// Neither joint: not known yet (the loop has not run), and the first known value is the start.
  using ReadWanted = std::function<MicroscopeJoints()>;
  MicroscopeClient(int domain_id, const NetworkConfig& network, ReadWanted wanted);
  ~MicroscopeClient();
  MicroscopeClient(const MicroscopeClient&) = delete;
  MicroscopeClient& operator=(const MicroscopeClient&) = delete;

  /// The slave's latest state, none before the first (any thread).
  std::optional<MicroscopeJoints> slave_state() const;
  std::uint64_t commands_sent() const { return sent_.load(); }

 private:
  void run();

  Participant participant_;
  ReadWanted wanted_;
  dds_entity_t command_writer_ = 0, state_reader_ = 0, waitset_ = 0;
  mutable std::mutex mutex_;
  std::optional<MicroscopeJoints> state_;
  std::atomic<std::uint64_t> sent_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace mc::net

#pragma once
/// @file
/// The DDS link between the real-time loop and the peer process. The loop only
/// pushes and pops NetSample through two SpscRing (send(), receive(): wait-free, no allocation,
/// no DDS call); a link thread does every DDS write and take, maps between NetSample and the ROS 2
/// types (ros_mapping.h), refuses and counts what the network sends out of bounds, and reads the
/// watchdog's statuses every millisecond: matched peers, liveliness and requested deadlines.
/// peer_alive() is their verdict, one atomic load for the loop's watchdogs (remote_slave.h,
/// remote_master.h).
///
/// A master link publishes the master's topics of the table (topics.h) and subscribes to the
/// slave's, and the other way round; each link ignores its own participant's samples.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <thread>

#include <dds/dds.h>

#include "microcobot/net/net_sample.h"
#include "microcobot/net/participant.h"
#include "microcobot/net/topics.h"
#include "microcobot/runtime/spsc_ring.h"

namespace mc::net {

struct LinkConfig {
  int domain_id = 0;
  Role role = Role::kSlave;
  NetworkConfig network;  ///< interface and discovery peers (default: loopback)
  NetLimits limits;
  std::size_t ring_capacity = 256;  ///< samples each way (0.25 s of one 1 kHz topic)
  /// How long the link thread waits for incoming data before it looks at the outgoing ring:
  /// the added latency of a sample the loop sends (the loop never wakes the thread: no DDS call).
  double poll_period_s = 1e-4;
  void validate() const;
};

/// A snapshot of the link's counters.
struct LinkStats {
  std::uint64_t written = 0;          ///< samples written to DDS
  std::uint64_t write_failed = 0;     ///< dds_write refused
  std::uint64_t not_published = 0;    ///< sent on a channel this role does not publish (dropped)
  std::uint64_t send_dropped = 0;     ///< the outgoing ring was full (the loop's push failed)
  std::uint64_t received = 0;         ///< valid samples passed to the loop
  std::uint64_t receive_dropped = 0;  ///< valid samples dropped: the incoming ring was full
  std::array<std::uint64_t, kRejectionCount> rejected{};  ///< refused samples, by Rejection
  std::uint64_t deadline_missed = 0;                      ///< requested deadlines missed on the state topics
  std::uint64_t liveliness_lost = 0;  ///< writers of the state topics that lost their liveliness
  bool peer_matched = false;          ///< every state topic has a matched peer both ways
  bool peer_alive = false;            ///< Link::peer_alive() at the snapshot
  std::uint64_t rejected_total() const;
};

class Link {
 public:
  /// Creates the participant, topics, readers and writers, and starts the link thread. Throws
  /// InvalidParams (config) or ComputationFailed (DDS).
  explicit Link(const LinkConfig& config);
  /// Stops the thread and deletes every DDS entity (the domain with its last participant).
  ~Link();
  Link(const Link&) = delete;
  Link& operator=(const Link&) = delete;

  /// Loop side: queues `s` for the link thread. False when the ring is full (counted).
  bool send(const NetSample& s) noexcept { return outbound_.push(s); }
  /// Loop side: the next sample from the peer, validated; false when none is waiting.
  bool receive(NetSample& s) noexcept { return inbound_.pop(s); }

  /// Not for the loop: waits until the link thread has written everything queued and every
  /// reliable sample (e-stop, mode) is acknowledged by the matched readers, or `timeout_s` passed.
  /// True when all of it happened in time.
  bool flush(double timeout_s);

  LinkStats stats() const;
  bool peer_matched() const { return peer_matched_.load(std::memory_order_acquire); }
  /// Loop side (one atomic load): DDS itself sees the peer. Every state topic is matched both
  /// ways, each state reader has a writer whose liveliness lease (kStateLease_s) holds, and each
  /// has had a valid sample since it matched and since it last missed its requested deadline
  /// (kStateDeadline_s): a peer that is present but has sent nothing yet is not alive. False
  /// within the deadline plus a status poll (1 ms) of a peer that falls silent, at once when it
  /// leaves cleanly, within the lease when its process dies.
  bool peer_alive() const noexcept { return peer_alive_.load(std::memory_order_acquire); }
  Role role() const { return config_.role; }
  int domain_id() const { return config_.domain_id; }

 private:
  void run() noexcept;
  void write(const NetSample& s) noexcept;
  void take(Channel c) noexcept;
  void poll_statuses() noexcept;

  LinkConfig config_;
  Participant participant_;
  std::array<dds_entity_t, kChannelCount> topics_{};
  std::array<dds_entity_t, kChannelCount> writers_{};  ///< 0 where the peer publishes
  std::array<dds_entity_t, kChannelCount> readers_{};  ///< 0 where this role publishes
  dds_entity_t waitset_ = 0;
  runtime::SpscRing<NetSample> outbound_, inbound_;

  std::atomic<bool> stop_{false};
  std::atomic<bool> peer_matched_{false}, peer_alive_{false};
  std::atomic<std::uint64_t> written_{0}, write_failed_{0}, not_published_{0}, received_{0},
      deadline_missed_{0}, liveliness_lost_{0};
  /// Link thread only: a state reader has had no valid sample since the start, since its writer
  /// matched, or since it missed its deadline.
  std::array<bool, kChannelCount> awaiting_sample_{};
  std::array<std::atomic<std::uint64_t>, kRejectionCount> rejected_{};
  std::thread thread_;
};

}  // namespace mc::net

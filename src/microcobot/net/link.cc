#include "microcobot/net/link.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "microcobot/core/error.h"
#include "microcobot/net/ros_mapping.h"

namespace mc::net {

namespace {

// Samples taken per reader and wake-up: keep-last 1 holds at most one on the state topics.
constexpr std::uint32_t kTakeBatch = 8;
// Statuses (matches, liveliness, deadlines) are read this often: the watchdog's resolution.
constexpr std::int64_t kStatusPeriod_ns = 1'000'000;

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// DDS handles of entities this link created are deleted in reverse order on failure too.
void delete_all(dds_entity_t waitset, const std::array<dds_entity_t, kChannelCount>& readers,
                const std::array<dds_entity_t, kChannelCount>& writers,
                const std::array<dds_entity_t, kChannelCount>& topics) {
  if (waitset > 0) dds_delete(waitset);
  for (auto e : readers)
    if (e > 0) dds_delete(e);
  for (auto e : writers)
    if (e > 0) dds_delete(e);
  for (auto e : topics)
    if (e > 0) dds_delete(e);
}

}  // namespace

void LinkConfig::validate() const {
  limits.validate();
  network.validate();
  if (ring_capacity < 1 || ring_capacity > (1u << 20))
    throw InvalidParams("ring_capacity", "must be within [1, 1048576]", static_cast<double>(ring_capacity));
  if (!(poll_period_s >= 1e-6 && poll_period_s <= 0.1))
    throw InvalidParams("poll_period_s", "must be within [1e-06, 0.1] s", poll_period_s);
}

std::uint64_t LinkStats::rejected_total() const {
  std::uint64_t n = 0;
  for (auto r : rejected) n += r;
  return n;
}

Link::Link(const LinkConfig& config)
    : config_((config.validate(), config)),
      participant_(config.domain_id, config.network),
      outbound_(config.ring_capacity),
      inbound_(config.ring_capacity) {
  awaiting_sample_.fill(true);
  const dds_entity_t pp = participant_.handle();
  try {
    for (const TopicSpec& spec : topic_table()) {
      const auto i = static_cast<std::size_t>(spec.channel);
      dds_qos_t* qos = make_qos(spec);
      topics_[i] =
          dds_create_topic(pp, descriptor(spec.type), std::string(spec.dds_name).c_str(), qos, nullptr);
      if (topics_[i] < 0) {
        dds_delete_qos(qos);
        check_dds(topics_[i], "cannot create a topic");
      }
      if (spec.publisher == config_.role) {
        writers_[i] = dds_create_writer(pp, topics_[i], qos, nullptr);
      } else {
        // A process that holds both ends (a test) must not read its own samples back.
        dds_qset_ignorelocal(qos, DDS_IGNORELOCAL_PARTICIPANT);
        readers_[i] = dds_create_reader(pp, topics_[i], qos, nullptr);
      }
      dds_delete_qos(qos);
      check_dds(writers_[i] < 0 ? writers_[i] : readers_[i], "cannot create a reader or writer");
    }
    waitset_ = check_dds(dds_create_waitset(pp), "cannot create a waitset");
    for (std::size_t i = 0; i < kChannelCount; ++i) {
      if (readers_[i] <= 0) continue;
      check_dds(dds_set_status_mask(readers_[i], DDS_DATA_AVAILABLE_STATUS), "cannot set a status mask");
      check_dds(dds_waitset_attach(waitset_, readers_[i], static_cast<dds_attach_t>(i)),
                "cannot attach a reader");
    }
  } catch (...) {
    delete_all(waitset_, readers_, writers_, topics_);
    throw;
  }
  thread_ = std::thread([this] { run(); });
}

Link::~Link() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  delete_all(waitset_, readers_, writers_, topics_);
}

bool Link::flush(double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (outbound_.size() > 0) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  // The ring is empty once the thread popped the last sample; its write follows at once.
  std::this_thread::sleep_for(std::chrono::microseconds(500));
  for (std::size_t i = 0; i < kChannelCount; ++i) {
    if (writers_[i] <= 0 || topic_table()[i].reliability != Reliability::kReliable) continue;
    const double left = std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
    const auto wait = static_cast<dds_duration_t>(std::llround(std::max(left, 0.0) * 1e9));
    if (dds_wait_for_acks(writers_[i], wait) < 0) return false;
  }
  return true;
}

LinkStats Link::stats() const {
  LinkStats s;
  s.written = written_.load();
  s.write_failed = write_failed_.load();
  s.not_published = not_published_.load();
  s.send_dropped = outbound_.dropped();
  s.received = received_.load();
  s.receive_dropped = inbound_.dropped();
  for (std::size_t i = 0; i < kRejectionCount; ++i) s.rejected[i] = rejected_[i].load();
  s.deadline_missed = deadline_missed_.load();
  s.liveliness_lost = liveliness_lost_.load();
  s.peer_matched = peer_matched_.load();
  s.peer_alive = peer_alive_.load();
  return s;
}

void Link::run() noexcept {
  const auto timeout = static_cast<dds_duration_t>(std::llround(config_.poll_period_s * 1e9));
  std::int64_t next_poll_ns = 0;
  while (!stop_.load(std::memory_order_acquire)) {
    NetSample s;
    while (outbound_.pop(s)) write(s);
    dds_waitset_wait(waitset_, nullptr, 0, timeout);
    for (std::size_t i = 0; i < kChannelCount; ++i) {
      if (readers_[i] > 0) take(static_cast<Channel>(i));
    }
    if (const std::int64_t now = steady_ns(); now >= next_poll_ns) {
      next_poll_ns = now + kStatusPeriod_ns;
      poll_statuses();
    }
  }
  // What the loop queued last (e.g. a final e-stop) still goes out.
  NetSample s;
  while (outbound_.pop(s)) write(s);
}

void Link::write(const NetSample& s) noexcept {
  const auto i = static_cast<std::size_t>(s.channel);
  if (i >= kChannelCount || writers_[i] <= 0) {
    not_published_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  dds_return_t rc = DDS_RETCODE_OK;
  switch (topic(s.channel).type) {
    case RosType::kPoseStamped: {
      geometry_msgs_msg_dds__PoseStamped_ m;
      to_ros(s, m);
      rc = dds_write(writers_[i], &m);
      break;
    }
    case RosType::kWrenchStamped: {
      geometry_msgs_msg_dds__WrenchStamped_ m;
      to_ros(s, m);
      rc = dds_write(writers_[i], &m);
      break;
    }
    case RosType::kJointState: {
      sensor_msgs_msg_dds__JointState_ m;
      JointStateBuffer buf;
      to_ros(s, buf, m);
      rc = dds_write(writers_[i], &m);
      break;
    }
    case RosType::kVector3Stamped: {
      geometry_msgs_msg_dds__Vector3Stamped_ m;
      to_ros(s, m);
      rc = dds_write(writers_[i], &m);
      break;
    }
    case RosType::kBool: {
      std_msgs_msg_dds__Bool_ m;
      to_ros(s, m);
      rc = dds_write(writers_[i], &m);
      break;
    }
    case RosType::kDiagnosticArray: {
      diagnostic_msgs_msg_dds__DiagnosticArray_ m;
      DiagnosticsBuffer buf;
      to_ros(s, buf, m);
      rc = dds_write(writers_[i], &m);
      break;
    }
  }
  (rc < 0 ? write_failed_ : written_).fetch_add(1, std::memory_order_relaxed);
}

void Link::take(Channel c) noexcept {
  const auto i = static_cast<std::size_t>(c);
  void* samples[kTakeBatch] = {};
  dds_sample_info_t infos[kTakeBatch];
  // Loaned samples: Cyclone deserialises into its own buffers, returned below.
  const dds_return_t n = dds_take(readers_[i], samples, infos, kTakeBatch, kTakeBatch);
  if (n <= 0) return;
  const std::int64_t now = steady_ns();
  for (dds_return_t k = 0; k < n; ++k) {
    if (!infos[k].valid_data) continue;
    NetSample s;
    Rejection r = Rejection::kNone;
    switch (topic(c).type) {
      case RosType::kPoseStamped:
        r = from_ros(*static_cast<const geometry_msgs_msg_dds__PoseStamped_*>(samples[k]), c, config_.limits,
                     s);
        break;
      case RosType::kWrenchStamped:
        r = from_ros(*static_cast<const geometry_msgs_msg_dds__WrenchStamped_*>(samples[k]), c,
                     config_.limits, s);
        break;
      case RosType::kJointState:
        r = from_ros(*static_cast<const sensor_msgs_msg_dds__JointState_*>(samples[k]), c, config_.limits, s);
        break;
      case RosType::kVector3Stamped:
        r = from_ros(*static_cast<const geometry_msgs_msg_dds__Vector3Stamped_*>(samples[k]), c,
                     config_.limits, s);
        break;
      case RosType::kBool:
        r = from_ros(*static_cast<const std_msgs_msg_dds__Bool_*>(samples[k]), c, s);
        break;
      case RosType::kDiagnosticArray:
        r = from_ros(*static_cast<const diagnostic_msgs_msg_dds__DiagnosticArray_*>(samples[k]), c, s);
        break;
    }
    if (r != Rejection::kNone) {
      rejected_[static_cast<std::size_t>(r)].fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    s.received_ns = now;
    awaiting_sample_[i] = false;
    if (inbound_.push(s)) {
      received_.fetch_add(1, std::memory_order_relaxed);
    }
  }
  dds_return_loan(readers_[i], samples, n);
}

void Link::poll_statuses() noexcept {
  bool matched = true, alive = true;
  for (std::size_t i = 0; i < kChannelCount; ++i) {
    if (topic_table()[i].rate_Hz <= 0) continue;  // latched topics: matched with the state ones
    if (readers_[i] > 0) {
      dds_subscription_matched_status_t m{};
      const bool reader_matched =
          dds_get_subscription_matched_status(readers_[i], &m) >= 0 && m.current_count > 0;
      if (!reader_matched) matched = false;
      if (!reader_matched || m.current_count_change > 0)
        awaiting_sample_[i] = true;  // a new peer: data first
      dds_liveliness_changed_status_t l{};
      if (dds_get_liveliness_changed_status(readers_[i], &l) < 0 || l.alive_count == 0) alive = false;
      if (l.not_alive_count_change > 0)
        liveliness_lost_.fetch_add(static_cast<std::uint64_t>(l.not_alive_count_change),
                                   std::memory_order_relaxed);
      dds_requested_deadline_missed_status_t d{};
      if (dds_get_requested_deadline_missed_status(readers_[i], &d) >= 0 && d.total_count_change > 0) {
        deadline_missed_.fetch_add(d.total_count_change, std::memory_order_relaxed);
        awaiting_sample_[i] = true;  // until the next valid sample (take())
      }
      if (awaiting_sample_[i]) alive = false;
    }
    if (writers_[i] > 0) {
      dds_publication_matched_status_t m{};
      if (dds_get_publication_matched_status(writers_[i], &m) < 0 || m.current_count == 0) matched = false;
    }
  }
  peer_matched_.store(matched, std::memory_order_release);
  peer_alive_.store(matched && alive, std::memory_order_release);
}

}  // namespace mc::net

#include "microcobot/net/microscope_link.h"

#include <chrono>
#include <cmath>
#include <string>

namespace mc::net {

namespace {

constexpr std::size_t kTakeMicroscopeBatch = 8;
constexpr auto kMicroscopePollPeriod = std::chrono::milliseconds(20);
constexpr auto kMicroscopeStatePeriod = std::chrono::milliseconds(100);  // kMicroscopeStateRate_Hz

std::int64_t microscope_stamp_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// A setting (commands): reliable and latched, so that a slave that starts later takes the last.
// A state: reliable, volatile (republished at 10 Hz), as /diagnostics.
dds_qos_t* microscope_topic_qos(bool latched) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(qos, latched ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  return qos;
}

dds_entity_t make_joint_topic(dds_entity_t pp, std::string_view name, const char* what) {
  return check_dds(dds_create_topic(pp, &sensor_msgs_msg_dds__JointState__desc, std::string(name).c_str(),
                                    nullptr, nullptr),
                   what);
}

enum class MicroscopeTopic { kCommand, kState };
enum class EndpointKind { kReader, kWriter };

// A reader or a writer of one of the two topics, with its QoS (the command latched, the state not).
dds_entity_t make_endpoint(dds_entity_t pp, MicroscopeTopic which, EndpointKind end) {
  const bool command = which == MicroscopeTopic::kCommand;
  const dds_entity_t topic =
      make_joint_topic(pp, command ? kMicroscopeCommandDdsName : kMicroscopeStateDdsName,
                       command ? "microscope: the command topic" : "microscope: the state topic");
  dds_qos_t* qos = microscope_topic_qos(command);
  const dds_entity_t e = end == EndpointKind::kReader ? dds_create_reader(pp, topic, qos, nullptr)
                                                      : dds_create_writer(pp, topic, qos, nullptr);
  dds_delete_qos(qos);
  return check_dds(e, command ? "microscope: cannot create the command's endpoint"
                              : "microscope: cannot create the state's endpoint");
}

dds_entity_t make_reader_waitset(dds_entity_t pp, dds_entity_t reader, const char* what) {
  const dds_entity_t ws = check_dds(dds_create_waitset(pp), what);
  const dds_entity_t cond = check_dds(dds_create_readcondition(reader, DDS_ANY_STATE), what);
  check_dds(dds_waitset_attach(ws, cond, reader), what);
  return ws;
}

// Takes what `reader` holds; `each` gets every valid sample's verdict and joints.
template <class Each>
void take_joints(dds_entity_t reader, Each&& each) {
  void* samples[kTakeMicroscopeBatch] = {};
  dds_sample_info_t infos[kTakeMicroscopeBatch];
  for (;;) {
    const dds_return_t n = dds_take(reader, samples, infos, kTakeMicroscopeBatch, kTakeMicroscopeBatch);
    if (n <= 0) return;
    for (dds_return_t k = 0; k < n; ++k) {
      if (!infos[k].valid_data) continue;
      MicroscopeJoints j;
      const MicroscopeRejection r =
          from_ros(*static_cast<const sensor_msgs_msg_dds__JointState_*>(samples[k]), j);
      each(r, j);
    }
    dds_return_loan(reader, samples, n);
  }
}

void write_joints(dds_entity_t writer, MicroscopeJoints j) {
  j.stamp_ns = microscope_stamp_ns();
  sensor_msgs_msg_dds__JointState_ m;
  MicroscopeJointBuffer buf;
  to_ros(j, buf, m);
  dds_write(writer, &m);
}

bool joints_differ(const MicroscopeJoints& a, const MicroscopeJoints& b) {
  return a.objective != b.objective || a.has_focus != b.has_focus ||
         std::abs(a.focus_z_m - b.focus_z_m) > 1e-9;
}

}  // namespace

MicroscopeServer::MicroscopeServer(int domain_id, const NetworkConfig& network, OnCommand on_command,
                                   ReadState read_state)
    : participant_(domain_id, network),
      on_command_(std::move(on_command)),
      read_state_(std::move(read_state)) {
  const dds_entity_t pp = participant_.handle();
  command_reader_ = make_endpoint(pp, MicroscopeTopic::kCommand, EndpointKind::kReader);
  state_writer_ = make_endpoint(pp, MicroscopeTopic::kState, EndpointKind::kWriter);
  waitset_ = make_reader_waitset(pp, command_reader_, "microscope: the command waitset");
  thread_ = std::thread([this] { run(); });
}

// The participant's deletion deletes the topics, the reader, the writer and the waitset with it.
MicroscopeServer::~MicroscopeServer() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

MicroscopeServerStats MicroscopeServer::stats() const {
  MicroscopeServerStats s;
  s.commands = commands_.load();
  s.states = states_.load();
  for (std::size_t i = 0; i < s.refused.size(); ++i) s.refused[i] = refused_[i].load();
  return s;
}

void MicroscopeServer::take_commands() {
  take_joints(command_reader_, [this](MicroscopeRejection r, const MicroscopeJoints& j) {
    if (r != MicroscopeRejection::kNone) {
      refused_[static_cast<std::size_t>(r)].fetch_add(1);
      return;
    }
    on_command_(j);
    commands_.fetch_add(1);
  });
}

void MicroscopeServer::publish(const MicroscopeJoints& state) {
  write_joints(state_writer_, state);
  states_.fetch_add(1);
}

void MicroscopeServer::run() {
  MicroscopeJoints last;
  bool published = false;
  auto last_at = std::chrono::steady_clock::now();
  while (!stop_.load()) {
    dds_waitset_wait(waitset_, nullptr, 0, DDS_MSECS(20));
    take_commands();
    const MicroscopeJoints now_state = read_state_();
    if (!now_state.has_focus && now_state.objective < 0) continue;  // not known yet
    const auto now = std::chrono::steady_clock::now();
    // At 10 Hz, and while the drive moves at most every 20 ms (a state is a few hundred bytes).
    if (!published || now - last_at >= kMicroscopeStatePeriod ||
        (joints_differ(now_state, last) && now - last_at >= kMicroscopePollPeriod)) {
      publish(now_state);
      last = now_state;
      last_at = now;
      published = true;
    }
  }
}

MicroscopeClient::MicroscopeClient(int domain_id, const NetworkConfig& network, ReadWanted wanted)
    : participant_(domain_id, network), wanted_(std::move(wanted)) {
  const dds_entity_t pp = participant_.handle();
  command_writer_ = make_endpoint(pp, MicroscopeTopic::kCommand, EndpointKind::kWriter);
  state_reader_ = make_endpoint(pp, MicroscopeTopic::kState, EndpointKind::kReader);
  waitset_ = make_reader_waitset(pp, state_reader_, "microscope: the state waitset");
  thread_ = std::thread([this] { run(); });
}

MicroscopeClient::~MicroscopeClient() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

std::optional<MicroscopeJoints> MicroscopeClient::slave_state() const {
  std::lock_guard lock(mutex_);
  return state_;
}

void MicroscopeClient::run() {
  std::optional<MicroscopeJoints> baseline;  // what the slave was last told (or the start)
  auto next_poll = std::chrono::steady_clock::now();
  while (!stop_.load()) {
    dds_waitset_wait(waitset_, nullptr, 0, DDS_MSECS(20));
    take_joints(state_reader_, [this](MicroscopeRejection r, const MicroscopeJoints& j) {
      if (r != MicroscopeRejection::kNone || !j.has_focus || j.objective < 0) return;  // not a state
      std::lock_guard lock(mutex_);
      state_ = j;
    });
    const auto now = std::chrono::steady_clock::now();
    if (now < next_poll) continue;
    next_poll = now + kMicroscopePollPeriod;
    const MicroscopeJoints wanted = wanted_();
    if (!wanted.has_focus && wanted.objective < 0) continue;  // this end does not know it yet
    if (!baseline) {
      baseline = wanted;  // the start: the operator has asked nothing yet
      continue;
    }
    if (!joints_differ(wanted, *baseline)) continue;
    // Both joints, so that the latched command alone is the whole setting.
    write_joints(command_writer_, wanted);
    baseline = wanted;
    sent_.fetch_add(1);
  }
}

}  // namespace mc::net

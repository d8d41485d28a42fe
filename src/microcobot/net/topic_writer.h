#pragma once
/// @file
/// One DDS topic and its writer on a participant, with the count of the samples written and of
/// those DDS refused: what each of the slave's side publishers (/tf, the positioner's pose, the
/// camera's images) is made of besides its message.
///
/// The participant owns both entities: deleting it deletes them, so a TopicWriter is declared
/// after the Participant it writes on and needs no destructor of its own.

#include <cstdint>
#include <memory>
#include <string_view>

#include <dds/dds.h>

namespace mc::net {

/// A QoS policy set, deleted with its owner.
struct QosDeleter {
  void operator()(dds_qos_t* q) const noexcept { dds_delete_qos(q); }
};
using QosPtr = std::unique_ptr<dds_qos_t, QosDeleter>;

class TopicWriter {
 public:
  /// Creates the topic `dds_name` of `type` on `participant` and its writer, both with `qos` (the
  /// caller keeps it). Throws ComputationFailed naming `what` and Cyclone's reason.
  TopicWriter(dds_entity_t participant, const dds_topic_descriptor_t& type, std::string_view dds_name,
              const dds_qos_t* qos, std::string_view what);
  TopicWriter(const TopicWriter&) = delete;
  TopicWriter& operator=(const TopicWriter&) = delete;

  /// Writes `sample` (of the topic's generated type). False when DDS refused it (counted).
  bool write(const void* sample);
  dds_entity_t writer() const { return writer_; }

  std::uint64_t written() const { return written_; }
  std::uint64_t failures() const { return failures_; }

 private:
  dds_entity_t topic_ = 0, writer_ = 0;
  std::uint64_t written_ = 0, failures_ = 0;  // the publishing thread
};

}  // namespace mc::net

#include "microcobot/net/topic_writer.h"

#include <string>

#include "microcobot/net/participant.h"

namespace mc::net {

TopicWriter::TopicWriter(dds_entity_t participant, const dds_topic_descriptor_t& type,
                         std::string_view dds_name, const dds_qos_t* qos, std::string_view what) {
  const std::string name(dds_name), prefix(what);
  topic_ = check_dds(dds_create_topic(participant, &type, name.c_str(), qos, nullptr),
                     (prefix + ": cannot create the topic " + name).c_str());
  writer_ = check_dds(dds_create_writer(participant, topic_, qos, nullptr),
                      (prefix + ": cannot create the writer of " + name).c_str());
}

bool TopicWriter::write(const void* sample) {
  if (dds_write(writer_, sample) < 0) {
    ++failures_;
    return false;
  }
  ++written_;
  return true;
}

}  // namespace mc::net

#include "microcobot/net/participant.h"

#include <map>
#include <mutex>
#include <string>

#include "microcobot/core/error.h"
#include "microcobot/net/cyclone_config.h"

namespace mc::net {

namespace {

// The domains this process created, with their participant counts: dds_create_domain fails
// for a domain that exists, and deleting a domain deletes every participant in it.
struct DomainRef {
  dds_entity_t domain = 0;
  int participants = 0;
};
std::mutex g_domains_mutex;
std::map<int, DomainRef>& domains() {
  static std::map<int, DomainRef> m;
  return m;
}

}  // namespace

dds_return_t check_dds(dds_return_t rc, const char* what) {
  if (rc < 0) throw ComputationFailed(std::string("DDS: ") + what + ": " + dds_strretcode(rc));
  return rc;
}

Participant::Participant(int domain_id) : domain_id_(domain_id) {
  if (domain_id < 0 || domain_id > kMaxDomainId)
    throw InvalidParams("domain_id", "must be within [0, " + std::to_string(kMaxDomainId) + "]",
                        static_cast<double>(domain_id));
  const std::lock_guard lock(g_domains_mutex);
  DomainRef& ref = domains()[domain_id];
  if (ref.participants == 0) {
    const std::string config = loopback_config();
    const dds_entity_t d = dds_create_domain(static_cast<dds_domainid_t>(domain_id), config.c_str());
    if (d < 0) {
      domains().erase(domain_id);
      check_dds(d, "cannot create the domain");
    }
    ref.domain = d;
  }
  const dds_entity_t p = dds_create_participant(static_cast<dds_domainid_t>(domain_id), nullptr, nullptr);
  if (p < 0) {
    if (ref.participants == 0) {
      dds_delete(ref.domain);
      domains().erase(domain_id);
    }
    check_dds(p, "cannot create a participant");
  }
  participant_ = p;
  ++ref.participants;
}

Participant::~Participant() {
  const std::lock_guard lock(g_domains_mutex);
  dds_delete(participant_);
  auto it = domains().find(domain_id_);
  if (it != domains().end() && --it->second.participants == 0) {
    dds_delete(it->second.domain);
    domains().erase(it);
  }
}

}  // namespace mc::net

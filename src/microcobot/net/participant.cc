#include "microcobot/net/participant.h"

#include <cstdio>
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
  NetworkConfig network;
};
std::mutex g_domains_mutex;
std::map<int, DomainRef>& domains() {
  static std::map<int, DomainRef> m;
  return m;
}

/// Cyclone's log lines while a domain is created: a failure's reason (e.g. "eth9: does not match
/// an available interface") goes into the exception's one line instead of a second line on stderr.
class CycloneLogCapture {
 public:
  CycloneLogCapture() { dds_set_log_sink(&CycloneLogCapture::collect, this); }
  ~CycloneLogCapture() { dds_set_log_sink(nullptr, nullptr); }
  CycloneLogCapture(const CycloneLogCapture&) = delete;
  CycloneLogCapture& operator=(const CycloneLogCapture&) = delete;

  /// The messages, without trailing periods and line ends, joined by "; ".
  const std::string& text() const { return text_; }

 private:
  static void collect(void* self, const dds_log_data_t* d) {
    auto* c = static_cast<CycloneLogCapture*>(self);
    std::string m(d->message, d->size);  // the text alone (hdrsize is the default sink's header)
    while (!m.empty() && (m.back() == '\n' || m.back() == '.' || m.back() == ' ')) m.pop_back();
    if (m.empty()) return;
    if (!c->text_.empty()) c->text_ += "; ";
    c->text_ += m;
  }
  std::string text_;
};

/// Why a port Cyclone could not bind is taken, for the domain's error: ids above 101 put the
/// domain's ports (7400 + 250 x domain and up) in Linux's default ephemeral range (32768 and up),
/// where any program's socket bound to port 0 may hold one.
std::string address_in_use_hint(int domain_id, const std::string& log) {
  if (log.find("address in use") == std::string::npos) return "";
  std::string hint = " (another program holds the port";
  if (domain_id > kMaxPortableDomainId)
    hint +=
        "; domain ids above " + std::to_string(kMaxPortableDomainId) +
        " use ports in Linux's ephemeral range, where any program's socket may take them: choose one up to " +
        std::to_string(kMaxPortableDomainId);
  return hint + ")";
}

}  // namespace

dds_return_t check_dds(dds_return_t rc, const char* what) {
  if (rc < 0) throw ComputationFailed(std::string("DDS: ") + what + ": " + dds_strretcode(rc));
  return rc;
}

Participant::Participant(int domain_id, const NetworkConfig& network) : domain_id_(domain_id) {
  if (domain_id < 0 || domain_id > kMaxDomainId)
    throw InvalidParams("domain_id", "must be within [0, " + std::to_string(kMaxDomainId) + "]",
                        static_cast<double>(domain_id));
  const std::string config = cyclone_config(network);  // validates
  const std::lock_guard lock(g_domains_mutex);
  DomainRef& ref = domains()[domain_id];
  if (ref.participants > 0 && !(ref.network == network)) {
    throw InvalidParams("network", "domain " + std::to_string(domain_id) +
                                       " is already open in this process with another network configuration");
  }
  if (ref.participants == 0) {
    ref.network = network;
    dds_entity_t d = 0;
    std::string log;
    {
      const CycloneLogCapture capture;
      d = dds_create_domain(static_cast<dds_domainid_t>(domain_id), config.c_str());
      log = capture.text();
    }
    if (d < 0) {
      domains().erase(domain_id);
      throw ComputationFailed("DDS: cannot create domain " + std::to_string(domain_id) + " on interface '" +
                              network.interface + "': " + (log.empty() ? dds_strretcode(d) : log) +
                              address_in_use_hint(domain_id, log));
    }
    if (!log.empty()) std::fprintf(stderr, "DDS: %s\n", log.c_str());  // what Cyclone would have printed
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

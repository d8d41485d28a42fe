#pragma once
/// @file
/// A DDS domain participant on a given domain id with the link's network configuration
/// (cyclone_config.h). The domain is created with that configuration on first use in the process
/// and deleted with its last participant, so that Cyclone releases everything it allocated
/// (nothing left for the leak checker).

#include <dds/dds.h>

#include "microcobot/net/cyclone_config.h"

namespace mc::net {

class Participant {
 public:
  /// Throws InvalidParams if `domain_id` is outside [0, kMaxDomainId], if `network` is invalid
  /// or differs from the one the domain was opened with in this process, ComputationFailed if DDS
  /// refuses (the message carries Cyclone's reason).
  explicit Participant(int domain_id, const NetworkConfig& network = {});
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  dds_entity_t handle() const { return participant_; }
  int domain_id() const { return domain_id_; }

 private:
  int domain_id_;
  dds_entity_t participant_ = 0;
};

/// Throws ComputationFailed naming `what` and Cyclone's reason when `rc` is negative.
dds_return_t check_dds(dds_return_t rc, const char* what);

}  // namespace mc::net

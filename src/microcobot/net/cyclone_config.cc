#include "microcobot/net/cyclone_config.h"

namespace mc::net {

std::string loopback_config() {
  // Without multicast, discovery goes by unicast to the peers' participant indices 0..Max on
  // 127.0.0.1: a handful of processes per domain is what the link needs.
  return "<General>"
         "<Interfaces><NetworkInterface address=\"127.0.0.1\"/></Interfaces>"
         "<AllowMulticast>false</AllowMulticast>"
         "</General>"
         "<Discovery>"
         "<ParticipantIndex>auto</ParticipantIndex>"
         "<MaxAutoParticipantIndex>20</MaxAutoParticipantIndex>"
         "<Peers><Peer address=\"127.0.0.1\"/></Peers>"
         "</Discovery>";
}

}  // namespace mc::net

/* The platform's Cyclone configuration on loopback (docs/distributed.md, "Middleware
 * configuration"), written here from the documentation, for the wire tests' own C programs
 * (ros2_listener.c, ros2_talker.c). */
#ifndef MC_WIRE_LOOPBACK_CONFIG_H
#define MC_WIRE_LOOPBACK_CONFIG_H

static const char kLoopbackConfig[] =
    "<General>"
    "<Interfaces><NetworkInterface address=\"127.0.0.1\" multicast=\"true\"/></Interfaces>"
    "<AllowMulticast>spdp</AllowMulticast>"
    "</General>"
    "<Discovery>"
    "<ParticipantIndex>auto</ParticipantIndex>"
    "<MaxAutoParticipantIndex>20</MaxAutoParticipantIndex>"
    "<Peers><Peer address=\"127.0.0.1\"/></Peers>"
    "</Discovery>";

#endif

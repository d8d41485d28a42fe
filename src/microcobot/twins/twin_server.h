#pragma once
/// @file
/// The vendor-protocol twins served over TCP (`microcobot serve --emulate gcs2
/// --emulate anc300 --emulate mcs2 --emulate gcs2-hexapod`): one thread runs every listening socket and
/// connection (Boost.Asio), the twins' controller state, and the stage's heartbeat; it is the only
/// producer of the live platform's protocol ring (twins/live_stage.h) and never touches the loop
/// otherwise. The hexapod twin drives the platform's parallel positioner through the same stage
/// (`positioner: parallel`; refused without one).
///
/// Survives any client: lines are capped (longer ones answered with the protocol's error and
/// their rest discarded), a line left unfinished for `line_timeout_s` closes the connection
/// (slowloris), so does an unanswered login after `login_timeout_s`, a client that stops reading
/// its replies (more than `max_output_bytes` queued), and one over `max_clients`; a half-closed
/// socket gets its pending replies, then is closed. A client that goes away releases control:
/// the stage holds.
///
/// Authentication: on loopback nothing is asked of GCS and MCS2 clients, and the ANC300 console's
/// password prompt accepts the controller's factory password (123456) or the token. Off
/// loopback a token is required: the ANC300 password must be the token, a GCS or MCS2 client's
/// first line must be the token (then it is answered as any controller).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "microcobot/twins/anc300_twin.h"
#include "microcobot/twins/gcs2_hexapod_twin.h"
#include "microcobot/twins/gcs2_twin.h"
#include "microcobot/twins/mcs2_twin.h"
#include "microcobot/twins/twin_stage.h"

namespace mc::twins {

enum class Protocol { kGcs2, kAnc300, kMcs2, kGcs2Hexapod };
/// The protocol's name as `--emulate` spells it ("gcs2", "anc300", "mcs2", "gcs2-hexapod").
const char* protocol_name(Protocol p);

struct TwinEndpoint {
  Protocol protocol = Protocol::kGcs2;
  std::string address = "127.0.0.1";
  std::uint16_t port = 0;  ///< 0: a free one (ports() says which)
  /// mcs2 only: the channels without a sensor (bit n: channel n; Mcs2TwinParams).
  unsigned no_sensor_channels = 0;
};

/// Parses `gcs2[=ADDR:PORT]`, `anc300[=ADDR:PORT]`, `mcs2[=ADDR:PORT][,no_sensor=N[+M...]]` or
/// `gcs2-hexapod[=ADDR:PORT]` (`serve --emulate`; no_sensor: the MCS2 channels 0..3 built without
/// a sensor); the default ports are the controllers' (GCS and the C-887 50000, ANC300 7230, MCS2
/// 55551) on 127.0.0.1. Throws mc::UsageError naming the text.
TwinEndpoint parse_emulate(const std::string& text);

struct TwinServerParams {
  std::vector<TwinEndpoint> endpoints;
  std::string token;  ///< required off loopback (8..256 characters)
  std::size_t max_clients = 16;
  double line_timeout_s = 5.0;
  double login_timeout_s = 10.0;
  std::size_t max_output_bytes = 64 * 1024;
  double heartbeat_s = 0.02;  ///< the controlling client's heartbeat period (< command_timeout_s)
  Gcs2TwinParams gcs2;
  Anc300TwinParams anc300;
  Mcs2TwinParams mcs2;
  Gcs2HexapodTwinParams gcs2_hexapod;
  void validate() const;
};

struct TwinServerCounters {
  std::uint64_t accepted = 0, refused = 0, closed_hostile = 0, lines = 0;
};

class TwinServer {
 public:
  /// `stage` must outlive the server. Throws mc::Error on bad parameters, and for a gcs2-hexapod
  /// endpoint on a stage without a parallel positioner.
  TwinServer(TwinStage& stage, TwinServerParams params);
  ~TwinServer();
  TwinServer(const TwinServer&) = delete;
  TwinServer& operator=(const TwinServer&) = delete;

  /// Binds every endpoint (throws mc::InvalidInput naming the one that cannot be bound) and
  /// starts the protocol thread.
  void start();
  /// Closes every connection (their clients release control: the stage holds), joins. Idempotent.
  void stop();
  /// The bound port of each endpoint, in order (after start()).
  std::vector<std::uint16_t> ports() const;
  TwinServerCounters counters() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mc::twins

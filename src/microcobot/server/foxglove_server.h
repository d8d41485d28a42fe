#pragma once
/// @file
/// A generic Foxglove WebSocket (protocol v1) + HTTP server: publishes JSON telemetry on
/// advertised channels to subscribed clients, hands client-published messages to a callback and
/// serves a fixed map of HTTP resources (e.g. a browser console). It knows nothing of the
/// platform. The transport (Boost.Beast) lives in foxglove_server.cc, ws_session.cc and
/// http_session.cc behind the private server_core.h, so this header is cheap to include. Limits
/// and behaviour: docs/console.md, "Protocol".

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "microcobot/server/foxglove_protocol.h"

namespace mc::server {

/// Where the server listens and the bounds it puts on every client (docs/architecture.md, network).
struct ServerOptions {
  /// IPv4 or IPv6 address to bind; loopback unless told otherwise.
  std::string address = "127.0.0.1";
  /// TCP port; 0 picks a free one (see FoxgloveServer::port()).
  std::uint16_t port = 8080;
  /// When non-empty, a WebSocket upgrade must carry `?token=<token>` (else HTTP 401).
  std::string token;
  /// Largest client WebSocket message; a larger one is discarded with an error status.
  std::size_t max_message_bytes = 64 * 1024;
  /// Open connections (HTTP and WebSocket) at most; more are answered HTTP 503.
  std::size_t max_connections = 64;
  /// Per connection token bucket (burst = one second's worth); excess messages are dropped with
  /// one warning status per second.
  double max_client_messages_per_s = 2000;
  /// Outgoing bytes queued per client; beyond it the oldest messageData are dropped (publishers
  /// never wait). A client whose queue of other messages (status, advertise) grows past twice this
  /// is disconnected.
  std::size_t max_queued_bytes_per_client = 4 << 20;
  /// A WebSocket that receives nothing for this long is pinged at half of it and closed at it.
  double idle_timeout_s = 30;
  /// HTTP request (header + body) must arrive within this; also the keep-alive idle time.
  double http_timeout_s = 10;
  /// Threads running the network I/O (sessions run on strands).
  int threads = 1;

  /// Throws mc::InvalidParams naming the field and the constraint.
  void validate() const;
};

/// A resource served on HTTP GET/HEAD of its path (e.g. "/" -> the console's index.html).
struct HttpResource {
  std::string content_type;
  std::string body;
};

/// The answer of the dynamic HTTP handler (FoxgloveServer::on_http_get).
struct HttpReply {
  int status = 200;
  std::string content_type = "text/plain; charset=utf-8";
  std::string body;            ///< the answer, unless `file` is set
  std::filesystem::path file;  ///< a file streamed from disk (404 when it cannot be opened)
  /// When set: `Content-Disposition: attachment; filename="<name>"` (a download).
  std::string attachment_name;
  /// When > 0: `Refresh: <s>` (a browser reloads the page, e.g. while a result is being made).
  int refresh_s = 0;
};

/// A message a client published on one of its advertised channels. The views are valid only
/// during the callback.
struct ClientMessage {
  ClientId client = 0;
  ClientChannelId channel = 0;
  std::string_view topic;
  std::string_view schema_name;
  std::string_view payload;
};

/// Counters for tests and metrics (monotonic since construction).
struct ServerCounters {
  std::uint64_t messages_received = 0;    ///< client WebSocket messages read (any kind)
  std::uint64_t messages_rejected = 0;    ///< client messages refused (malformed, unknown, oversized, rate)
  std::uint64_t messages_dropped = 0;     ///< messageData dropped for slow clients
  std::uint64_t messages_superseded = 0;  ///< latest-only messageData replaced by a newer one while queued
  std::uint64_t messages_sent = 0;        ///< WebSocket messages written to clients
  std::uint64_t bytes_sent = 0;           ///< WebSocket payload bytes written to clients
  std::uint64_t connections_accepted = 0;
  std::uint64_t connections_refused = 0;  ///< over max_connections (503 or closed)
};

/// A Foxglove WebSocket + HTTP server (docs/console.md, "Protocol").
///
/// Threading: publish(), send_status(), add_channel(), client_count(), subscriber_count(),
/// counters() and stop()
/// may be called from any thread. The callbacks run on server threads (one session's callbacks
/// are serialised; with threads > 1 different sessions' may run concurrently); they must be
/// quick, must not throw (an exception is caught and reported as a status error) and must be set
/// before start().
class FoxgloveServer {
 public:
  /// `name` goes into serverInfo; `http` maps GET paths to resources. Throws InvalidParams.
  FoxgloveServer(ServerOptions options, std::string name, std::map<std::string, HttpResource> http = {});
  ~FoxgloveServer();
  FoxgloveServer(const FoxgloveServer&) = delete;
  FoxgloveServer& operator=(const FoxgloveServer&) = delete;

  /// Adds a server channel; before start() or after (then advertised to connected clients).
  ChannelId add_channel(const ChannelSpec& spec);
  /// The spec a channel was added with (nullopt for an unknown id).
  std::optional<ChannelSpec> channel(ChannelId id) const;
  /// Metadata sent in serverInfo (set before start()).
  void set_metadata(std::map<std::string, std::string> metadata);

  /// Messages clients publish on their `json` channels.
  void on_client_message(std::function<void(const ClientMessage&)> callback);
  /// GET/HEAD of a path outside the fixed resources (the path without its query). Runs on a
  /// server thread: it must be quick (look at files, hand long work to another thread); nullopt
  /// answers 404 and an exception 500, each with a one-line message. With a token, these
  /// requests must carry `?token=` as the WebSocket upgrade does (else 401).
  void on_http_get(std::function<std::optional<HttpReply>(std::string_view path)> handler);
  /// A WebSocket client finished its handshake.
  void on_connect(std::function<void(ClientId)> callback);
  /// A WebSocket client went away (closed, timed out, failed or stop()).
  void on_disconnect(std::function<void(ClientId)> callback);
  /// The server refused a client's message (the status it sent: level, id, message), e.g.
  /// `malformed-json`; the application may log it (the recordings' events).
  void on_reject(
      std::function<void(ClientId, StatusLevel, std::string_view id, std::string_view message)> callback);

  /// Binds, listens and starts the I/O threads. Throws mc::InvalidParams for a bad address and
  /// mc::InvalidInput (one line, with the address) when the port cannot be bound.
  void start();
  /// The bound port (after start(); the chosen one when ServerOptions::port is 0).
  std::uint16_t port() const;

  /// Sends `payload` on `channel` to every subscriber, stamped `log_time_ns`. Copies the payload
  /// once (shared by subscribers), never blocks on a client; unknown channels are ignored.
  void publish(ChannelId channel, std::uint64_t log_time_ns, std::string_view payload);
  /// Sends a status message to one client (ignored when it is gone).
  void send_status(ClientId client, StatusLevel level, std::string_view message, std::string_view id = "");
  /// Sends a status message to every client.
  void broadcast_status(StatusLevel level, std::string_view message, std::string_view id = "");

  /// Connected WebSocket clients.
  std::size_t client_count() const;
  /// Clients subscribed to `channel` (0 for an unknown one).
  std::size_t subscriber_count(ChannelId channel) const;
  /// A snapshot of the counters.
  ServerCounters counters() const;

  /// Closes the listener and every connection and joins the threads; idempotent.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mc::server

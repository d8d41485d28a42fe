#pragma once
/// @file
/// Internal to the server's transport: the WebSocket session of one Foxglove client (its
/// implementation is ws_session.cc). Includes Beast, like server_core.h: for the transport's
/// translation units only.

#include <atomic>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <unordered_map>

#include "microcobot/server/server_core.h"

namespace mc::server {

namespace http = beast::http;
namespace websocket = beast::websocket;

namespace detail {

/// One WebSocket client: the handshake, the client's operations (subscriptions, its channels,
/// its messages) and the queue of messages written to it. Reads and writes run on the
/// session's strand; subscribed() and the methods marked "Any thread" may be called from others.
class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(Core& srv, beast::tcp_stream&& stream, Slot&& slot, ClientId id);

  ClientId id() const { return id_; }

  /// Accepts the upgrade `req` (the HTTP session read it) and starts reading.
  void run(http::request<http::string_body>&& req);

  bool subscribed(ChannelId channel) const;

  /// Queues messageData for `channel` when subscribed; copies `payload` into `shared` on first use.
  /// Any thread.
  void offer(ChannelId channel, std::uint64_t log_time_ns, std::string_view payload,
             std::shared_ptr<const std::string>& shared, bool latest_only);

  /// Queues a JSON text message. Any thread.
  void send_text(std::string text);

  void send_status(StatusLevel level, std::string_view message, std::string_view id);

  /// Starts the WebSocket close (going away); stop() cuts what does not finish in time. Any thread.
  void close();

  /// Ends the session once: unregisters it and tells the application. Strand, or stop() after
  /// the I/O threads have been joined.
  void finish();

 private:
  double bucket_capacity() const;
  void on_accept(const error_code& ec);
  void schedule_flush_locked();
  void flush();
  void on_write(const error_code& ec, std::size_t bytes);
  void hard_close();
  void do_read();
  void on_read(const error_code& ec, std::size_t /*bytes*/);
  bool take_token();
  void reject(std::string_view id, std::string_view message, StatusLevel level = StatusLevel::kError);
  void on_message();
  void handle_op(const ClientOp& op);
  void subscribe(const Subscription& sub);
  void advertise(const ClientChannel& ch);
  void handle_binary(std::string_view frame);

  Core& srv_;
  websocket::stream<beast::tcp_stream> ws_;
  Slot slot_;
  const ClientId id_;
  http::request<http::string_body> req_;
  bool registered_ = false;
  std::atomic<bool> finished_{false};

  // Strand only.
  beast::flat_buffer rbuf_;
  bool discarding_ = false;
  std::size_t discarded_ = 0;
  double tokens_ = 0;
  Clock::time_point last_refill_;
  Clock::time_point last_rate_warning_{};
  std::uint64_t rate_dropped_ = 0;
  std::unordered_map<ClientChannelId, ClientChannel> client_channels_;
  Outgoing current_;  // being written (guarded by writing_)

  // Shared with publishers (any thread).
  mutable std::mutex mu_;
  std::unordered_map<SubscriptionId, ChannelId> subs_;
  std::unordered_map<ChannelId, SubscriptionId> subs_by_channel_;
  std::deque<Outgoing> queue_;
  std::size_t queued_bytes_ = 0;
  std::size_t control_bytes_ = 0;
  bool writing_ = false;
  bool flush_posted_ = false;
  bool closed_ = false;
};

}  // namespace detail
}  // namespace mc::server

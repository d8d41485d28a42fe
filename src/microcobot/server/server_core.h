#pragma once
/// @file
/// Internal to the server's transport, not part of the library's interface: the state that
/// FoxgloveServer and its sessions share (detail::Core) and the small types they pass between
/// them. It includes Boost.Asio and Beast, which compile slowly, so only the transport's
/// translation units include it (foxglove_server.cc, ws_session.cc, http_session.cc, each kept
/// out of the unity build); everything else sees foxglove_server.h.

#include <array>
#include <atomic>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

#include "microcobot/server/foxglove_server.h"

namespace mc::server {

namespace beast = boost::beast;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using Clock = std::chrono::steady_clock;
using error_code = boost::system::error_code;

namespace detail {

class WsSession;

inline Clock::duration to_duration(double seconds) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

inline std::string_view sv(beast::string_view s) { return {s.data(), s.size()}; }
inline beast::string_view bsv(std::string_view s) { return {s.data(), s.size()}; }

/// Decrements a connection counter when the connection object goes away.
class Slot {
 public:
  Slot() = default;
  explicit Slot(std::atomic<std::size_t>* counter) : counter_(counter) {}
  Slot(Slot&& o) noexcept : counter_(std::exchange(o.counter_, nullptr)) {}
  Slot& operator=(Slot&&) = delete;
  Slot(const Slot&) = delete;
  ~Slot() {
    if (counter_ != nullptr) counter_->fetch_sub(1);
  }

 private:
  std::atomic<std::size_t>* counter_ = nullptr;
};

/// One message waiting to be written to a client. messageData shares its payload between
/// subscribers; only its 13-byte header is per client.
struct Outgoing {
  std::shared_ptr<const std::string> data;
  std::array<char, kMessageDataHeaderBytes> header{};
  bool binary = false;
  ChannelId channel = 0;  ///< of a messageData
  std::size_t size() const { return (binary ? header.size() : 0) + (data ? data->size() : 0); }
};

/// The server's state, shared by the sessions (FoxgloveServer::Impl is this).
struct Core {
  ServerOptions opt;
  std::string name;
  std::map<std::string, HttpResource> http;
  std::function<std::optional<HttpReply>(std::string_view)> http_handler;
  std::map<std::string, std::string> metadata;
  std::string session_id;
  std::function<void(const ClientMessage&)> on_message;
  std::function<void(ClientId)> on_connect;
  std::function<void(ClientId)> on_disconnect;
  std::function<void(ClientId, StatusLevel, std::string_view, std::string_view)> on_reject;

  std::atomic<bool> started{false};
  std::atomic<bool> stopped{false};
  std::uint16_t bound_port = 0;

  // Lock order: channels_mu, then sessions_mu, then a session's mutex.
  mutable std::mutex channels_mu;
  std::set<ChannelId> latest_only;  ///< channels whose queued message a newer one replaces
  std::vector<Channel> channels;
  std::atomic<ChannelId> next_channel{1};
  mutable std::mutex sessions_mu;
  std::unordered_map<ClientId, std::shared_ptr<WsSession>> sessions;
  std::atomic<ClientId> next_client{1};

  std::atomic<std::size_t> open_connections{0};
  std::atomic<std::size_t> refusing{0};
  std::atomic<std::uint64_t> received{0}, rejected{0}, dropped{0}, superseded{0}, sent{0}, bytes_sent{0},
      accepted{0}, refused{0};

  // Declared last so that it (and the sessions its handlers own) goes first; stop() resets it
  // explicitly while everything above is alive.
  std::optional<net::io_context> ioc;
  std::optional<tcp::acceptor> acceptor;
  std::optional<net::steady_timer> accept_retry;
  std::optional<net::executor_work_guard<net::io_context::executor_type>> work;
  std::vector<std::thread> threads;

  void do_accept();
  void on_accept(const error_code& ec, tcp::socket socket);
  bool channel_exists(ChannelId id) const { return id >= 1 && id < next_channel.load(); }
  /// Registers a handshaken session and queues its serverInfo + advertise (under channels_mu so
  /// that no add_channel() is missed or sent twice).
  void register_session(const std::shared_ptr<WsSession>& s);
  void unregister_session(ClientId id);
};

/// Serves HTTP on an accepted connection (http_session.cc): answers the requests from the
/// resources, or hands the connection to a WsSession on a WebSocket upgrade. `slot` holds the
/// connection's place in its counter; `refuse` answers every request 503 (over max_connections).
void serve_http(Core& srv, tcp::socket&& socket, Slot&& slot, bool refuse);

}  // namespace detail
}  // namespace mc::server

// FoxgloveServer: the listener, the I/O threads and the public API over the sessions
// (ws_session.cc, http_session.cc), all sharing detail::Core (server_core.h). Includes Beast
// through ws_session.h, hence out of the unity build; the protocol's rules are in
// foxglove_protocol.cc.
#include "microcobot/server/foxglove_server.h"

#include <boost/asio/post.hpp>
#include <boost/asio/strand.hpp>
#include <chrono>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <unordered_map>
#include <utility>

#include "microcobot/core/error.h"
#include "microcobot/server/server_core.h"
#include "microcobot/server/ws_session.h"

namespace mc::server {

namespace {

/// Connections over max_connections that get a 503 answer; beyond, they are closed at once.
constexpr std::size_t kMaxRefusing = 16;
/// How long stop() lets clients complete the WebSocket close before cutting the connections.
constexpr auto kStopGrace = std::chrono::milliseconds(250);

}  // namespace

// ---------------------------------------------------------------------------------------------
// Core

namespace detail {

void Core::do_accept() {
  acceptor->async_accept(net::make_strand(*ioc), [this](const error_code& ec, tcp::socket socket) {
    on_accept(ec, std::move(socket));
  });
}

void Core::on_accept(const error_code& ec, tcp::socket socket) {
  if (stopped || !acceptor->is_open()) return;
  if (ec) {
    // Out of descriptors and the like: retry shortly rather than spin.
    accept_retry->expires_after(std::chrono::milliseconds(50));
    accept_retry->async_wait([this](const error_code& e) {
      if (!e && !stopped) do_accept();
    });
    return;
  }
  accepted.fetch_add(1, std::memory_order_relaxed);
  error_code ignored;
  socket.set_option(tcp::no_delay(true), ignored);  // live telemetry: no Nagle delay on small frames
  try {
    if (open_connections.fetch_add(1) < opt.max_connections) {
      serve_http(*this, std::move(socket), Slot(&open_connections), false);
    } else {
      open_connections.fetch_sub(1);
      refused.fetch_add(1, std::memory_order_relaxed);
      if (refusing.fetch_add(1) < kMaxRefusing) {
        serve_http(*this, std::move(socket), Slot(&refusing), true);
      } else {
        refusing.fetch_sub(1);
        socket.close(ignored);
      }
    }
  } catch (const std::exception&) {
    // Allocation failure: the connection is dropped, the server goes on.
  }
  do_accept();
}

void Core::register_session(const std::shared_ptr<WsSession>& s) {
  std::lock_guard ch_lock(channels_mu);
  {
    std::lock_guard lk(sessions_mu);
    sessions.emplace(s->id(), s);
  }
  ServerInfo info;
  info.name = name;
  info.metadata = metadata;
  info.session_id = session_id;
  s->send_text(server_info_json(info));
  s->send_text(advertise_json(channels));
}

void Core::unregister_session(ClientId id) {
  std::lock_guard lk(sessions_mu);
  sessions.erase(id);
}

}  // namespace detail

// ---------------------------------------------------------------------------------------------
// FoxgloveServer

struct FoxgloveServer::Impl : detail::Core {};

void ServerOptions::validate() const {
  require(!address.empty(), "server.address", "must not be empty");
  require(max_message_bytes >= 64 && max_message_bytes <= (64u << 20), "server.max_message_bytes",
          "must be in [64, 67108864]", static_cast<double>(max_message_bytes));
  require(max_connections >= 1 && max_connections <= 100000, "server.max_connections",
          "must be in [1, 100000]", static_cast<double>(max_connections));
  require_positive(max_client_messages_per_s, "server.max_client_messages_per_s");
  require(max_queued_bytes_per_client >= max_message_bytes + kMessageDataHeaderBytes,
          "server.max_queued_bytes_per_client", "must be >= max_message_bytes + 13",
          static_cast<double>(max_queued_bytes_per_client));
  require_in_range(idle_timeout_s, 0.01, 86400, "server.idle_timeout_s");
  require_in_range(http_timeout_s, 0.01, 86400, "server.http_timeout_s");
  require(threads >= 1 && threads <= 64, "server.threads", "must be in [1, 64]", threads);
}

FoxgloveServer::FoxgloveServer(ServerOptions options, std::string name,
                               std::map<std::string, HttpResource> http)
    : impl_(std::make_unique<Impl>()) {
  options.validate();
  impl_->opt = std::move(options);
  impl_->name = std::move(name);
  impl_->http = std::move(http);
  impl_->session_id = std::to_string(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                         std::chrono::system_clock::now().time_since_epoch())
                                         .count());
  impl_->ioc.emplace(impl_->opt.threads);
}

FoxgloveServer::~FoxgloveServer() { stop(); }

ChannelId FoxgloveServer::add_channel(const ChannelSpec& spec) {
  Impl& s = *impl_;
  std::lock_guard ch_lock(s.channels_mu);
  const Channel ch{s.next_channel.load(), spec};
  s.channels.push_back(ch);
  if (spec.latest_only) s.latest_only.insert(ch.id);
  s.next_channel.fetch_add(1);  // after the push: channel_exists() never sees a missing channel
  const std::string text = advertise_json({ch});
  std::lock_guard lk(s.sessions_mu);
  for (auto& [id, session] : s.sessions) session->send_text(text);
  return ch.id;
}

std::optional<ChannelSpec> FoxgloveServer::channel(ChannelId id) const {
  std::lock_guard lk(impl_->channels_mu);
  for (const auto& c : impl_->channels)
    if (c.id == id) return c.spec;
  return std::nullopt;
}

void FoxgloveServer::set_metadata(std::map<std::string, std::string> metadata) {
  std::lock_guard lk(impl_->channels_mu);
  impl_->metadata = std::move(metadata);
}

void FoxgloveServer::on_client_message(std::function<void(const ClientMessage&)> callback) {
  impl_->on_message = std::move(callback);
}
void FoxgloveServer::on_http_get(std::function<std::optional<HttpReply>(std::string_view)> handler) {
  impl_->http_handler = std::move(handler);
}
void FoxgloveServer::on_connect(std::function<void(ClientId)> callback) {
  impl_->on_connect = std::move(callback);
}
void FoxgloveServer::on_disconnect(std::function<void(ClientId)> callback) {
  impl_->on_disconnect = std::move(callback);
}
void FoxgloveServer::on_reject(
    std::function<void(ClientId, StatusLevel, std::string_view id, std::string_view message)> callback) {
  impl_->on_reject = std::move(callback);
}

void FoxgloveServer::start() {
  Impl& s = *impl_;
  if (s.stopped) throw mc::InvalidInput("server: start() after stop()");
  if (s.started) throw mc::InvalidInput("server: start() called twice");
  error_code ec;
  const auto address = net::ip::make_address(s.opt.address, ec);
  if (ec) {
    throw mc::InvalidParams("server.address",
                            "must be an IPv4 or IPv6 address (got \"" + one_line(s.opt.address) + "\")");
  }
  const tcp::endpoint endpoint(address, s.opt.port);
  const std::string where =
      (address.is_v6() ? "[" + s.opt.address + "]" : s.opt.address) + ":" + std::to_string(s.opt.port);
  s.acceptor.emplace(net::make_strand(*s.ioc));
  s.accept_retry.emplace(s.acceptor->get_executor());
  s.acceptor->open(endpoint.protocol(), ec);
  if (!ec) s.acceptor->set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) s.acceptor->bind(endpoint, ec);
  if (!ec) s.acceptor->listen(net::socket_base::max_listen_connections, ec);
  if (ec) {
    s.acceptor.reset();
    throw mc::InvalidInput("cannot listen on " + where + ": " + ec.message());
  }
  s.bound_port = s.acceptor->local_endpoint().port();
  s.started = true;
  s.work.emplace(s.ioc->get_executor());
  net::post(s.acceptor->get_executor(), [&s] { s.do_accept(); });
  for (int i = 0; i < s.opt.threads; ++i) {
    s.threads.emplace_back([&s] {
      for (;;) {
        try {
          s.ioc->run();
          return;
        } catch (...) {
          // A handler threw past its own guard: that session is lost, the server is not.
        }
      }
    });
  }
}

std::uint16_t FoxgloveServer::port() const { return impl_->bound_port; }

void FoxgloveServer::publish(ChannelId channel, std::uint64_t log_time_ns, std::string_view payload) {
  Impl& s = *impl_;
  if (!s.started || s.stopped) return;
  std::shared_ptr<const std::string> shared;  // made on the first subscriber, shared by the rest
  bool latest_only = false;
  {
    std::lock_guard ch_lock(s.channels_mu);
    latest_only = s.latest_only.count(channel) != 0;
  }
  std::lock_guard lk(s.sessions_mu);
  for (auto& [id, session] : s.sessions) session->offer(channel, log_time_ns, payload, shared, latest_only);
}

void FoxgloveServer::send_status(ClientId client, StatusLevel level, std::string_view message,
                                 std::string_view id) {
  Impl& s = *impl_;
  std::lock_guard lk(s.sessions_mu);
  const auto it = s.sessions.find(client);
  if (it != s.sessions.end()) it->second->send_status(level, message, id);
}

void FoxgloveServer::broadcast_status(StatusLevel level, std::string_view message, std::string_view id) {
  Impl& s = *impl_;
  const std::string text = status_json(level, message, id);
  std::lock_guard lk(s.sessions_mu);
  for (auto& [cid, session] : s.sessions) session->send_text(text);
}

std::size_t FoxgloveServer::client_count() const {
  std::lock_guard lk(impl_->sessions_mu);
  return impl_->sessions.size();
}

std::size_t FoxgloveServer::subscriber_count(ChannelId channel) const {
  std::lock_guard lk(impl_->sessions_mu);
  std::size_t n = 0;
  for (const auto& [id, session] : impl_->sessions) n += session->subscribed(channel) ? 1 : 0;
  return n;
}

ServerCounters FoxgloveServer::counters() const {
  const Impl& s = *impl_;
  ServerCounters c;
  c.messages_received = s.received.load();
  c.messages_rejected = s.rejected.load();
  c.messages_dropped = s.dropped.load();
  c.messages_superseded = s.superseded.load();
  c.messages_sent = s.sent.load();
  c.bytes_sent = s.bytes_sent.load();
  c.connections_accepted = s.accepted.load();
  c.connections_refused = s.refused.load();
  return c;
}

void FoxgloveServer::stop() {
  Impl& s = *impl_;
  if (s.stopped.exchange(true)) return;
  if (s.started) {
    net::post(s.acceptor->get_executor(), [&s] {
      error_code ignored;
      s.acceptor->close(ignored);
      s.accept_retry->cancel();
    });
    {
      std::lock_guard lk(s.sessions_mu);
      for (auto& [id, session] : s.sessions) session->close();
    }
    // Let clients see a clean close; whatever is still open after the grace is cut.
    const auto deadline = Clock::now() + kStopGrace;
    while (Clock::now() < deadline) {
      {
        std::lock_guard lk(s.sessions_mu);
        if (s.sessions.empty()) break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    s.work.reset();
    s.ioc->stop();
    for (auto& t : s.threads) t.join();
    s.threads.clear();
  }
  std::unordered_map<ClientId, std::shared_ptr<detail::WsSession>> left;
  {
    std::lock_guard lk(s.sessions_mu);
    left.swap(s.sessions);
  }
  for (auto& [id, session] : left) session->finish();
  left.clear();
  // Destroys the pending handlers and the sessions they own while the rest of Impl is alive.
  s.accept_retry.reset();
  s.acceptor.reset();
  s.ioc.reset();
}

}  // namespace mc::server

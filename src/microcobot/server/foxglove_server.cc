// The Beast/Asio transport of FoxgloveServer. This is the only file of the library that includes
// Beast (it compiles slowly); the protocol's rules are in foxglove_protocol.cc.
#include "microcobot/server/foxglove_server.h"

#include <algorithm>
#include <atomic>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cmath>
#include <deque>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <unordered_map>
#include <vector>

#include "microcobot/core/error.h"

namespace mc::server {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using Clock = std::chrono::steady_clock;
using error_code = boost::system::error_code;

namespace {

constexpr std::size_t kHttpHeaderLimit = 8 * 1024;
constexpr std::size_t kHttpBodyLimit = 16 * 1024;
/// Bytes asked from Beast per read; a message is assembled from such chunks.
constexpr std::size_t kReadChunk = 64 * 1024;
/// A client may publish on at most this many channels at once.
constexpr std::size_t kMaxClientChannels = 256;
/// Connections over max_connections that get a 503 answer; beyond, they are closed at once.
constexpr std::size_t kMaxRefusing = 16;
/// How long stop() lets clients complete the WebSocket close before cutting the connections.
constexpr auto kStopGrace = std::chrono::milliseconds(250);

Clock::duration to_duration(double seconds) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

/// Equality whose time depends only on the length of `expected` (the secret), not on where the
/// strings differ.
bool constant_time_equal(std::string_view expected, std::string_view given) {
  unsigned diff = expected.size() == given.size() ? 0u : 1u;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const auto g = i < given.size() ? static_cast<unsigned char>(given[i]) : 0u;
    diff |= static_cast<unsigned char>(expected[i]) ^ g;
  }
  return diff == 0;
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::string percent_decode(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size()) {
      const int hi = hex_value(s[i + 1]);
      const int lo = hex_value(s[i + 2]);
      if (hi >= 0 && lo >= 0) {
        out += static_cast<char>(hi * 16 + lo);
        i += 2;
        continue;
      }
    }
    out += s[i] == '+' ? ' ' : s[i];
  }
  return out;
}

/// The value of query parameter `key` in a request target, percent-decoded.
std::optional<std::string> query_param(std::string_view target, std::string_view key) {
  const auto q = target.find('?');
  if (q == std::string_view::npos) return std::nullopt;
  std::string_view rest = target.substr(q + 1);
  while (!rest.empty()) {
    const auto amp = rest.find('&');
    const std::string_view pair = rest.substr(0, amp);
    const auto eq = pair.find('=');
    if (pair.substr(0, eq) == key) {
      return eq == std::string_view::npos ? std::string() : percent_decode(pair.substr(eq + 1));
    }
    if (amp == std::string_view::npos) break;
    rest = rest.substr(amp + 1);
  }
  return std::nullopt;
}

/// Whether a Sec-WebSocket-Protocol header lists the Foxglove subprotocol.
bool offers_subprotocol(std::string_view header) {
  while (!header.empty()) {
    const auto comma = header.find(',');
    std::string_view item = header.substr(0, comma);
    while (!item.empty() && (item.front() == ' ' || item.front() == '\t')) item.remove_prefix(1);
    while (!item.empty() && (item.back() == ' ' || item.back() == '\t')) item.remove_suffix(1);
    if (item == kSubprotocol) return true;
    if (comma == std::string_view::npos) break;
    header.remove_prefix(comma + 1);
  }
  return false;
}

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

class WsSession;

std::string_view sv(beast::string_view s) { return {s.data(), s.size()}; }
beast::string_view bsv(std::string_view s) { return {s.data(), s.size()}; }

}  // namespace

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

// ---------------------------------------------------------------------------------------------
// WebSocket session

namespace {

class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(Core& srv, beast::tcp_stream&& stream, Slot&& slot, ClientId id)
      : srv_(srv), ws_(std::move(stream)), slot_(std::move(slot)), id_(id) {
    tokens_ = bucket_capacity();
    last_refill_ = Clock::now();
  }

  ClientId id() const { return id_; }

  void run(http::request<http::string_body>&& req) {
    req_ = std::move(req);
    beast::get_lowest_layer(ws_).expires_never();  // the websocket's own timeouts take over
    websocket::stream_base::timeout t{};
    t.handshake_timeout = to_duration(srv_.opt.http_timeout_s);
    t.idle_timeout = to_duration(srv_.opt.idle_timeout_s / 2);  // ping at half, close at the whole
    t.keep_alive_pings = true;
    ws_.set_option(t);
    ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& res) {
      res.set(http::field::sec_websocket_protocol, bsv(kSubprotocol));
      res.set(http::field::server, "microcobot");
    }));
    // Messages up to max_message_bytes are read; larger ones are discarded chunk by chunk (with
    // an error status) up to this hard bound, beyond which Beast closes the connection.
    ws_.read_message_max(std::max<std::size_t>(16u << 20, 16 * srv_.opt.max_message_bytes));
    ws_.auto_fragment(false);
    ws_.async_accept(req_, [self = shared_from_this()](const error_code& ec) { self->on_accept(ec); });
  }

  bool subscribed(ChannelId channel) const {
    std::lock_guard lk(mu_);
    return !closed_ && subs_by_channel_.count(channel) != 0;
  }

  /// Queues messageData for `channel` when subscribed; copies `payload` into `shared` on first use.
  /// Any thread.
  void offer(ChannelId channel, std::uint64_t log_time_ns, std::string_view payload,
             std::shared_ptr<const std::string>& shared, bool latest_only) {
    std::lock_guard lk(mu_);
    if (closed_) return;
    const auto it = subs_by_channel_.find(channel);
    if (it == subs_by_channel_.end()) return;
    if (latest_only) {
      const auto queued = std::find_if(queue_.begin(), queue_.end(), [channel](const Outgoing& o) {
        return o.binary && o.channel == channel;
      });
      if (queued != queue_.end()) {
        queued_bytes_ -= queued->size();
        queue_.erase(queued);
        srv_.superseded.fetch_add(1, std::memory_order_relaxed);
      }
    }
    const std::size_t size = kMessageDataHeaderBytes + payload.size();
    const std::size_t limit = srv_.opt.max_queued_bytes_per_client;
    // Oldest telemetry goes first: the newest sample is what a live view wants.
    while (queued_bytes_ + size > limit) {
      const auto old = std::find_if(queue_.begin(), queue_.end(), [](const Outgoing& o) { return o.binary; });
      if (old == queue_.end()) break;
      queued_bytes_ -= old->size();
      queue_.erase(old);
      srv_.dropped.fetch_add(1, std::memory_order_relaxed);
    }
    if (queued_bytes_ + size > limit) {
      srv_.dropped.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    if (!shared) shared = std::make_shared<const std::string>(payload);
    Outgoing o;
    o.data = shared;
    o.header = message_data_header(it->second, log_time_ns);
    o.binary = true;
    o.channel = channel;
    queued_bytes_ += o.size();
    queue_.push_back(std::move(o));
    schedule_flush_locked();
  }

  /// Queues a JSON text message. Any thread.
  void send_text(std::string text) {
    std::lock_guard lk(mu_);
    if (closed_) return;
    Outgoing o;
    o.data = std::make_shared<const std::string>(std::move(text));
    queued_bytes_ += o.size();
    control_bytes_ += o.size();
    queue_.push_back(std::move(o));
    if (control_bytes_ > 2 * srv_.opt.max_queued_bytes_per_client) {
      // The client reads nothing while it keeps provoking replies: let it go.
      closed_ = true;
      queue_.clear();
      net::post(ws_.get_executor(), [self = shared_from_this()] { self->hard_close(); });
      return;
    }
    schedule_flush_locked();
  }

  void send_status(StatusLevel level, std::string_view message, std::string_view id) {
    send_text(status_json(level, message, id));
  }

  /// Starts the WebSocket close (going away); stop() cuts what does not finish in time. Any thread.
  void close() {
    net::post(ws_.get_executor(), [self = shared_from_this()] {
      if (self->finished_) return;
      self->ws_.async_close(websocket::close_code::going_away,
                            [self](const error_code&) { self->hard_close(); });
    });
  }

  /// Ends the session once: unregisters it and tells the application. Strand, or stop() after
  /// the I/O threads have been joined.
  void finish() {
    if (finished_.exchange(true)) return;
    {
      std::lock_guard lk(mu_);
      closed_ = true;
      queue_.clear();
      queued_bytes_ = control_bytes_ = 0;
    }
    error_code ignored;
    beast::get_lowest_layer(ws_).socket().close(ignored);
    if (registered_) {
      srv_.unregister_session(id_);
      if (srv_.on_disconnect) {
        try {
          srv_.on_disconnect(id_);
        } catch (...) {  // the application's problem; the server carries on
        }
      }
    }
  }

 private:
  double bucket_capacity() const { return std::max(1.0, srv_.opt.max_client_messages_per_s); }

  void on_accept(const error_code& ec) {
    if (ec || srv_.stopped) {
      finish();
      return;
    }
    registered_ = true;
    srv_.register_session(shared_from_this());
    if (srv_.on_connect) {
      try {
        srv_.on_connect(id_);
      } catch (...) {
      }
    }
    do_read();
  }

  void schedule_flush_locked() {
    if (writing_ || flush_posted_ || closed_) return;
    flush_posted_ = true;
    net::post(ws_.get_executor(), [self = shared_from_this()] { self->flush(); });
  }

  void flush() {
    std::unique_lock lk(mu_);
    flush_posted_ = false;
    if (writing_ || queue_.empty() || closed_) return;
    current_ = std::move(queue_.front());
    queue_.pop_front();
    queued_bytes_ -= current_.size();
    if (!current_.binary) control_bytes_ -= current_.size();
    writing_ = true;
    lk.unlock();
    auto done = [self = shared_from_this()](const error_code& e, std::size_t n) { self->on_write(e, n); };
    ws_.binary(current_.binary);
    if (current_.binary) {
      const std::array<net::const_buffer, 2> bufs{net::buffer(current_.header), net::buffer(*current_.data)};
      ws_.async_write(bufs, std::move(done));
    } else {
      ws_.async_write(net::buffer(*current_.data), std::move(done));
    }
  }

  void on_write(const error_code& ec, std::size_t bytes) {
    {
      std::lock_guard lk(mu_);
      writing_ = false;
      current_ = Outgoing{};
    }
    if (ec) {
      hard_close();  // the read side sees the failure and finishes the session
      return;
    }
    srv_.sent.fetch_add(1, std::memory_order_relaxed);
    srv_.bytes_sent.fetch_add(bytes, std::memory_order_relaxed);
    flush();
  }

  void hard_close() {
    {
      std::lock_guard lk(mu_);
      closed_ = true;
    }
    error_code ignored;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ignored);
    beast::get_lowest_layer(ws_).socket().close(ignored);
  }

  void do_read() {
    ws_.async_read_some(rbuf_, kReadChunk, [self = shared_from_this()](const error_code& ec, std::size_t n) {
      self->on_read(ec, n);
    });
  }

  void on_read(const error_code& ec, std::size_t /*bytes*/) {
    if (ec) {
      finish();
      return;
    }
    if (!discarding_ && rbuf_.size() > srv_.opt.max_message_bytes) discarding_ = true;
    if (discarding_) {
      discarded_ += rbuf_.size();
      rbuf_.clear();
    }
    if (ws_.is_message_done()) {
      try {
        on_message();
      } catch (const std::exception& e) {
        reject("internal-error", std::string("message handling failed: ") + e.what());
      } catch (...) {
        reject("internal-error", "message handling failed");
      }
      rbuf_.clear();
      discarding_ = false;
      discarded_ = 0;
    }
    do_read();
  }

  bool take_token() {
    const auto now = Clock::now();
    const double dt = std::chrono::duration<double>(now - last_refill_).count();
    last_refill_ = now;
    tokens_ = std::min(bucket_capacity(), tokens_ + dt * srv_.opt.max_client_messages_per_s);
    if (tokens_ < 1.0) return false;
    tokens_ -= 1.0;
    return true;
  }

  void reject(std::string_view id, std::string_view message, StatusLevel level = StatusLevel::kError) {
    srv_.rejected.fetch_add(1, std::memory_order_relaxed);
    send_status(level, message, id);
    if (srv_.on_reject) srv_.on_reject(id_, level, id, message);
  }

  void on_message() {
    srv_.received.fetch_add(1, std::memory_order_relaxed);
    if (!take_token()) {
      srv_.rejected.fetch_add(1, std::memory_order_relaxed);
      ++rate_dropped_;
      const auto now = Clock::now();
      if (now - last_rate_warning_ >= std::chrono::seconds(1)) {
        last_rate_warning_ = now;
        send_status(StatusLevel::kWarning,
                    "rate limit exceeded: " + std::to_string(rate_dropped_) + " message(s) dropped (limit " +
                        std::to_string(static_cast<long long>(srv_.opt.max_client_messages_per_s)) +
                        " messages/s)",
                    "rate-limit");
        rate_dropped_ = 0;
      }
      return;
    }
    if (discarding_) {
      reject("oversized", "message of " + std::to_string(discarded_) + " bytes exceeds the limit of " +
                              std::to_string(srv_.opt.max_message_bytes) + " bytes; dropped");
      return;
    }
    const auto data = rbuf_.cdata();
    const std::string_view text(static_cast<const char*>(data.data()), data.size());
    if (ws_.got_text()) {
      handle_op(parse_client_text(text));
    } else {
      handle_binary(text);
    }
  }

  void handle_op(const ClientOp& op) {
    if (const auto* e = std::get_if<ProtocolError>(&op)) {
      reject(e->id, e->message);
    } else if (const auto* s = std::get_if<SubscribeOp>(&op)) {
      for (const Subscription& sub : s->subscriptions) subscribe(sub);
    } else if (const auto* u = std::get_if<UnsubscribeOp>(&op)) {
      for (SubscriptionId sid : u->subscription_ids) {
        std::unique_lock lk(mu_);
        const auto it = subs_.find(sid);
        if (it == subs_.end()) {
          lk.unlock();
          reject("unknown-subscription", "unsubscribe: unknown subscription id " + std::to_string(sid));
          continue;
        }
        subs_by_channel_.erase(it->second);
        subs_.erase(it);
      }
    } else if (const auto* a = std::get_if<ClientAdvertiseOp>(&op)) {
      for (const ClientChannel& ch : a->channels) advertise(ch);
    } else if (const auto* ua = std::get_if<ClientUnadvertiseOp>(&op)) {
      for (ClientChannelId cid : ua->channel_ids) {
        if (client_channels_.erase(cid) == 0) {
          reject("unknown-channel", "unadvertise: unknown client channel id " + std::to_string(cid));
        }
      }
    }
  }

  void subscribe(const Subscription& sub) {
    if (!srv_.channel_exists(sub.channel)) {
      reject("unknown-channel", "subscribe: unknown channel id " + std::to_string(sub.channel));
      return;
    }
    std::unique_lock lk(mu_);
    if (subs_.count(sub.id) != 0) {
      lk.unlock();
      reject("bad-subscription",
             "subscribe: subscription id " + std::to_string(sub.id) + " is already in use");
      return;
    }
    if (const auto it = subs_by_channel_.find(sub.channel); it != subs_by_channel_.end()) {
      const SubscriptionId existing = it->second;
      lk.unlock();
      reject("bad-subscription", "subscribe: channel " + std::to_string(sub.channel) +
                                     " is already subscribed (subscription " + std::to_string(existing) +
                                     ")");
      return;
    }
    subs_.emplace(sub.id, sub.channel);
    subs_by_channel_.emplace(sub.channel, sub.id);
  }

  void advertise(const ClientChannel& ch) {
    if (ch.encoding != "json") {
      reject("unsupported-encoding", "advertise: channel " + std::to_string(ch.id) + " has encoding \"" +
                                         one_line(ch.encoding, 32) + "\" (supported: json)");
    } else if (client_channels_.count(ch.id) != 0) {
      reject("bad-channel",
             "advertise: client channel id " + std::to_string(ch.id) + " is already advertised");
    } else if (client_channels_.size() >= kMaxClientChannels) {
      reject("bad-channel",
             "advertise: more than " + std::to_string(kMaxClientChannels) + " client channels");
    } else {
      client_channels_.emplace(ch.id, ch);
    }
  }

  void handle_binary(std::string_view frame) {
    const auto parsed = parse_client_binary(frame);
    if (const auto* e = std::get_if<ProtocolError>(&parsed)) {
      reject(e->id, e->message);
      return;
    }
    const auto& data = std::get<ClientMessageData>(parsed);
    const auto it = client_channels_.find(data.channel);
    if (it == client_channels_.end()) {
      reject("unknown-channel",
             "messageData on client channel " + std::to_string(data.channel) + " that was not advertised");
      return;
    }
    if (!srv_.on_message) return;
    ClientMessage m;
    m.client = id_;
    m.channel = data.channel;
    m.topic = it->second.topic;
    m.schema_name = it->second.schema_name;
    m.payload = data.payload;
    try {
      srv_.on_message(m);
    } catch (const std::exception& e) {
      reject("handler-error", "message on " + it->second.topic + " refused: " + e.what());
    }
  }

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

// ---------------------------------------------------------------------------------------------
// HTTP session: serves the resources, or upgrades to a WsSession.

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(Core& srv, tcp::socket&& socket, Slot&& slot, bool refuse)
      : srv_(srv), stream_(std::move(socket)), slot_(std::move(slot)), refuse_(refuse) {}

  void run() {
    net::dispatch(stream_.get_executor(), [self = shared_from_this()] { self->do_read(); });
  }

 private:
  void do_read() {
    parser_.emplace();
    parser_->header_limit(kHttpHeaderLimit);
    parser_->body_limit(kHttpBodyLimit);
    stream_.expires_after(refuse_ ? Clock::duration(std::chrono::seconds(2))
                                  : to_duration(srv_.opt.http_timeout_s));
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](const error_code& ec, std::size_t) { self->on_read(ec); });
  }

  void on_read(const error_code& ec) {
    if (ec == http::error::end_of_stream || ec == beast::error::timeout ||
        ec == net::error::operation_aborted) {
      close();
      return;
    }
    if (ec == http::error::header_limit) {
      respond(http::status::request_header_fields_too_large, "request header larger than 8192 bytes", 11,
              false);
      return;
    }
    if (ec == http::error::body_limit) {
      respond(http::status::payload_too_large, "request body larger than 16384 bytes", 11, false);
      return;
    }
    if (ec) {
      respond(http::status::bad_request, "malformed HTTP request", 11, false);
      return;
    }
    try {
      handle(parser_->release());
    } catch (const std::exception&) {
      close();
    }
  }

  void handle(http::request<http::string_body>&& req) {
    const unsigned version = req.version();
    if (refuse_) {
      respond(
          http::status::service_unavailable,
          "server busy: " + std::to_string(srv_.opt.max_connections) + " connections open (max_connections)",
          version, false);
      return;
    }
    if (srv_.stopped) {
      respond(http::status::service_unavailable, "server stopping", version, false);
      return;
    }
    if (websocket::is_upgrade(req)) {
      if (!srv_.opt.token.empty()) {
        const auto token = query_param(sv(req.target()), "token");
        if (!constant_time_equal(srv_.opt.token, token.value_or(std::string()))) {
          respond(http::status::unauthorized, "missing or wrong token (add ?token=... to the WebSocket URL)",
                  version, false);
          return;
        }
      }
      if (!offers_subprotocol(sv(req[http::field::sec_websocket_protocol]))) {
        respond(http::status::bad_request,
                "WebSocket upgrade must offer subprotocol " + std::string(kSubprotocol), version, false);
        return;
      }
      const ClientId id = srv_.next_client.fetch_add(1);
      upgraded_ = true;
      std::make_shared<WsSession>(srv_, std::move(stream_), std::move(slot_), id)->run(std::move(req));
      return;
    }
    const bool head = req.method() == http::verb::head;
    if (req.method() != http::verb::get && !head) {
      respond(http::status::method_not_allowed, "method not allowed (only GET and HEAD)", version,
              req.keep_alive(), true);
      return;
    }
    std::string_view path = sv(req.target());
    path = path.substr(0, path.find('?'));
    const auto it = srv_.http.find(std::string(path));
    if (it != srv_.http.end()) {
      auto res = std::make_shared<http::response<http::string_body>>(http::status::ok, version);
      res->set(http::field::content_type, it->second.content_type);
      if (head) {
        res->content_length(it->second.body.size());
      } else {
        res->body() = it->second.body;
        res->prepare_payload();
      }
      send(std::move(res), req.keep_alive());
      return;
    }
    std::optional<HttpReply> reply;
    if (srv_.http_handler && !srv_.opt.token.empty()) {
      // Dynamic resources are the platform's data (recordings): the token guards them as it
      // guards the WebSocket.
      const auto token = query_param(sv(req.target()), "token");
      if (!constant_time_equal(srv_.opt.token, token.value_or(std::string()))) {
        respond(http::status::unauthorized, "missing or wrong token (add ?token=... to the URL)", version,
                req.keep_alive(), false, head);
        return;
      }
    }
    if (srv_.http_handler) {
      try {
        reply = srv_.http_handler(path);
      } catch (const std::exception& e) {
        respond(http::status::internal_server_error, one_line(e.what(), 300), version, req.keep_alive(),
                false, head);
        return;
      }
    }
    if (!reply) {
      respond(http::status::not_found, "not found: " + one_line(path, 200), version, req.keep_alive(), false,
              head);
      return;
    }
    answer(std::move(*reply), version, req.keep_alive(), head);
  }

  /// A dynamic answer: a string, or a file streamed from disk.
  void answer(HttpReply reply, unsigned version, bool keep_alive, bool head) {
    const auto status = static_cast<http::status>(reply.status);
    auto decorate = [&](auto& res) {
      res.set(http::field::content_type, reply.content_type);
      if (!reply.attachment_name.empty())
        res.set(http::field::content_disposition, "attachment; filename=\"" + reply.attachment_name + "\"");
      if (reply.refresh_s > 0) res.set("Refresh", std::to_string(reply.refresh_s));
    };
    if (reply.file.empty()) {
      auto res = std::make_shared<http::response<http::string_body>>(status, version);
      decorate(*res);
      if (head) {
        res->content_length(reply.body.size());
      } else {
        res->body() = std::move(reply.body);
        res->prepare_payload();
      }
      send(std::move(res), keep_alive);
      return;
    }
    http::file_body::value_type file;
    error_code ec;
    file.open(reply.file.c_str(), beast::file_mode::scan, ec);
    if (ec) {
      respond(http::status::not_found, "not found: " + one_line(reply.file.filename().string(), 200), version,
              keep_alive, false, head);
      return;
    }
    const std::uint64_t size = file.size();
    if (head) {
      auto res = std::make_shared<http::response<http::empty_body>>(status, version);
      decorate(*res);
      res->content_length(size);
      send(std::move(res), keep_alive);
      return;
    }
    auto res = std::make_shared<http::response<http::file_body>>(
        std::piecewise_construct, std::make_tuple(std::move(file)), std::make_tuple(status, version));
    decorate(*res);
    res->prepare_payload();
    // A large download over a slow link may take longer than one request's timeout: allow
    // 1 MB/s on top of it.
    send(std::move(res), keep_alive, static_cast<double>(size) / 1e6);
  }

  /// A one-line text/plain answer.
  void respond(http::status status, const std::string& message, unsigned version, bool keep_alive,
               bool allow = false, bool head = false) {
    auto res = std::make_shared<http::response<http::string_body>>(status, version);
    res->set(http::field::content_type, "text/plain; charset=utf-8");
    if (allow) res->set(http::field::allow, "GET, HEAD");
    const std::string body = message + "\n";
    if (head) {
      res->content_length(body.size());
    } else {
      res->body() = body;
      res->prepare_payload();
    }
    send(std::move(res), keep_alive);
  }

  template <class Body>
  void send(std::shared_ptr<http::response<Body>> res, bool keep_alive, double extra_time_s = 0.0) {
    res->set(http::field::server, "microcobot");
    res->set(http::field::cache_control, "no-store");
    res->set("X-Content-Type-Options", "nosniff");
    res->keep_alive(keep_alive && !refuse_ && !srv_.stopped);
    const bool again = res->keep_alive();
    response_ = res;  // kept alive until written
    stream_.expires_after(to_duration(srv_.opt.http_timeout_s + extra_time_s));
    http::async_write(stream_, *res, [self = shared_from_this(), again](const error_code& ec, std::size_t) {
      self->response_.reset();
      if (!ec && again) {
        self->do_read();
      } else {
        self->close();
      }
    });
  }

  /// Half-closes, then reads and discards what the client still sends (for up to a second)
  /// before closing: closing with unread input would reset the connection and could destroy
  /// the answer just written (e.g. a 431 to a request that was not read to its end).
  void close() {
    if (upgraded_) return;  // the stream now belongs to the WsSession
    error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
    stream_.expires_after(std::chrono::seconds(1));
    drain();
  }

  void drain() {
    stream_.async_read_some(net::buffer(scratch_),
                            [self = shared_from_this()](const error_code& ec, std::size_t) {
                              if (ec) {
                                self->stream_.close();
                              } else {
                                self->drain();
                              }
                            });
  }

  Core& srv_;
  beast::tcp_stream stream_;
  Slot slot_;
  bool refuse_;
  bool upgraded_ = false;
  std::array<char, 4096> scratch_{};
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::shared_ptr<void> response_;
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Impl

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
      std::make_shared<HttpSession>(*this, std::move(socket), Slot(&open_connections), false)->run();
    } else {
      open_connections.fetch_sub(1);
      refused.fetch_add(1, std::memory_order_relaxed);
      if (refusing.fetch_add(1) < kMaxRefusing) {
        std::make_shared<HttpSession>(*this, std::move(socket), Slot(&refusing), true)->run();
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

// ---------------------------------------------------------------------------------------------
// FoxgloveServer

struct FoxgloveServer::Impl : Core {};

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
  std::unordered_map<ClientId, std::shared_ptr<WsSession>> left;
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

// The WebSocket session of one Foxglove client: the handshake, the client's operations and the
// queue of messages written to it. Compiles Beast's WebSocket stream, hence out of the unity
// build; the protocol's rules are in foxglove_protocol.cc.
#include "microcobot/server/ws_session.h"

#include <algorithm>
#include <array>
#include <boost/asio/post.hpp>
#include <chrono>
#include <exception>
#include <string>
#include <utility>
#include <variant>

namespace mc::server::detail {

namespace {

/// Bytes asked from Beast per read; a message is assembled from such chunks.
constexpr std::size_t kReadChunk = 64 * 1024;
/// A client may publish on at most this many channels at once.
constexpr std::size_t kMaxClientChannels = 256;

}  // namespace

WsSession::WsSession(Core& srv, beast::tcp_stream&& stream, Slot&& slot, ClientId id)
    : srv_(srv), ws_(std::move(stream)), slot_(std::move(slot)), id_(id) {
  tokens_ = bucket_capacity();
  last_refill_ = Clock::now();
}

void WsSession::run(http::request<http::string_body>&& req) {
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

bool WsSession::subscribed(ChannelId channel) const {
  std::lock_guard lk(mu_);
  return !closed_ && subs_by_channel_.count(channel) != 0;
}

void WsSession::offer(ChannelId channel, std::uint64_t log_time_ns, std::string_view payload,
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

void WsSession::send_text(std::string text) {
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

void WsSession::send_status(StatusLevel level, std::string_view message, std::string_view id) {
  send_text(status_json(level, message, id));
}

void WsSession::close() {
  net::post(ws_.get_executor(), [self = shared_from_this()] {
    if (self->finished_) return;
    self->ws_.async_close(websocket::close_code::going_away,
                          [self](const error_code&) { self->hard_close(); });
  });
}

void WsSession::finish() {
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

double WsSession::bucket_capacity() const { return std::max(1.0, srv_.opt.max_client_messages_per_s); }

void WsSession::on_accept(const error_code& ec) {
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

void WsSession::schedule_flush_locked() {
  if (writing_ || flush_posted_ || closed_) return;
  flush_posted_ = true;
  net::post(ws_.get_executor(), [self = shared_from_this()] { self->flush(); });
}

void WsSession::flush() {
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

void WsSession::on_write(const error_code& ec, std::size_t bytes) {
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

void WsSession::hard_close() {
  {
    std::lock_guard lk(mu_);
    closed_ = true;
  }
  error_code ignored;
  beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ignored);
  beast::get_lowest_layer(ws_).socket().close(ignored);
}

void WsSession::do_read() {
  ws_.async_read_some(rbuf_, kReadChunk, [self = shared_from_this()](const error_code& ec, std::size_t n) {
    self->on_read(ec, n);
  });
}

void WsSession::on_read(const error_code& ec, std::size_t /*bytes*/) {
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

bool WsSession::take_token() {
  const auto now = Clock::now();
  const double dt = std::chrono::duration<double>(now - last_refill_).count();
  last_refill_ = now;
  tokens_ = std::min(bucket_capacity(), tokens_ + dt * srv_.opt.max_client_messages_per_s);
  if (tokens_ < 1.0) return false;
  tokens_ -= 1.0;
  return true;
}

void WsSession::reject(std::string_view id, std::string_view message, StatusLevel level) {
  srv_.rejected.fetch_add(1, std::memory_order_relaxed);
  send_status(level, message, id);
  if (srv_.on_reject) srv_.on_reject(id_, level, id, message);
}

void WsSession::on_message() {
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

void WsSession::handle_op(const ClientOp& op) {
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

void WsSession::subscribe(const Subscription& sub) {
  if (!srv_.channel_exists(sub.channel)) {
    reject("unknown-channel", "subscribe: unknown channel id " + std::to_string(sub.channel));
    return;
  }
  std::unique_lock lk(mu_);
  if (subs_.count(sub.id) != 0) {
    lk.unlock();
    reject("bad-subscription", "subscribe: subscription id " + std::to_string(sub.id) + " is already in use");
    return;
  }
  if (const auto it = subs_by_channel_.find(sub.channel); it != subs_by_channel_.end()) {
    const SubscriptionId existing = it->second;
    lk.unlock();
    reject("bad-subscription", "subscribe: channel " + std::to_string(sub.channel) +
                                   " is already subscribed (subscription " + std::to_string(existing) + ")");
    return;
  }
  subs_.emplace(sub.id, sub.channel);
  subs_by_channel_.emplace(sub.channel, sub.id);
}

void WsSession::advertise(const ClientChannel& ch) {
  if (ch.encoding != "json") {
    reject("unsupported-encoding", "advertise: channel " + std::to_string(ch.id) + " has encoding \"" +
                                       one_line(ch.encoding, 32) + "\" (supported: json)");
  } else if (client_channels_.count(ch.id) != 0) {
    reject("bad-channel", "advertise: client channel id " + std::to_string(ch.id) + " is already advertised");
  } else if (client_channels_.size() >= kMaxClientChannels) {
    reject("bad-channel", "advertise: more than " + std::to_string(kMaxClientChannels) + " client channels");
  } else {
    client_channels_.emplace(ch.id, ch);
  }
}

void WsSession::handle_binary(std::string_view frame) {
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

}  // namespace mc::server::detail

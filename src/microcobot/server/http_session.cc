// The HTTP session of one connection: serves the fixed resources and the dynamic handler's
// replies, or hands the connection to a WsSession on a WebSocket upgrade. Compiles Beast's HTTP
// parser and serializers, hence out of the unity build.
#include <array>
#include <boost/asio/dispatch.hpp>
#include <chrono>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>

#include "microcobot/server/http_text.h"
#include "microcobot/server/ws_session.h"

namespace mc::server::detail {

namespace {

constexpr std::size_t kHttpHeaderLimit = 8 * 1024;
constexpr std::size_t kHttpBodyLimit = 16 * 1024;

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

void serve_http(Core& srv, tcp::socket&& socket, Slot&& slot, bool refuse) {
  std::make_shared<HttpSession>(srv, std::move(socket), std::move(slot), refuse)->run();
}

}  // namespace mc::server::detail

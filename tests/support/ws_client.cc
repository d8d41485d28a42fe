// The tests' Foxglove client: the only test file that includes Boost.Beast.
#include "support/ws_client.h"

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cctype>

namespace mc::test {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using error_code = boost::system::error_code;
using namespace std::chrono_literals;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace

struct WsClient::Impl {
  net::io_context ioc;
  websocket::stream<beast::tcp_stream> ws{ioc};
  websocket::response_type response;
  beast::flat_buffer buffer;
  // A read that timed out stays pending (a loaded machine is slow, not broken): the next read()
  // goes on waiting for it rather than starting a second one, which Beast forbids. Its state
  // lives here, not on the stack of the read() that started it.
  bool read_pending = false, read_done = false;
  error_code read_ec;

  // Connect, handshake, write and close have no such continuation: when one times out the
  // connection is given up, and its handlers run here, while the caller's stack they refer to
  // still exists (never later, into a frame that is gone).
  void abandon() {
    error_code ignored;
    beast::get_lowest_layer(ws).socket().close(ignored);
    ioc.restart();
    ioc.run();
    read_pending = false;
  }

  bool run_until(const bool& done, std::chrono::milliseconds timeout = kClientTimeout) {
    ioc.restart();
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!done) {
      const auto now = std::chrono::steady_clock::now();
      if (now >= deadline) return false;
      ioc.run_one_for(deadline - now);
    }
    return true;
  }
};

WsClient::WsClient() : impl_(std::make_unique<Impl>()) {}
WsClient::~WsClient() = default;

int WsClient::connect(std::uint16_t port, const std::string& target, bool subprotocol) {
  Impl& c = *impl_;
  bool done = false;
  error_code ec;
  beast::get_lowest_layer(c.ws).expires_after(kExchangeTimeout);
  beast::get_lowest_layer(c.ws).async_connect(tcp::endpoint(net::ip::address_v4::loopback(), port),
                                              [&](const error_code& e) {
                                                ec = e;
                                                done = true;
                                              });
  if (!c.run_until(done, kExchangeTimeout)) {
    c.abandon();
    return -1;
  }
  if (ec) return -1;
  if (subprotocol) {
    c.ws.set_option(websocket::stream_base::decorator([](websocket::request_type& req) {
      req.set(http::field::sec_websocket_protocol, "foxglove.websocket.v1");
    }));
  }
  done = false;
  c.ws.async_handshake(c.response, "127.0.0.1", target, [&](const error_code& e) {
    ec = e;
    done = true;
  });
  if (!c.run_until(done, kExchangeTimeout)) {
    c.abandon();
    return -1;
  }
  beast::get_lowest_layer(c.ws).expires_never();
  // A refused upgrade (401, 400, 503) is answered with its status; a connection closed or
  // timed out before any answer is -1 (the response would still say its default, 200).
  if (ec && c.response.result_int() == 200) return -1;
  return c.response.result_int();
}

std::string WsClient::response_header(const std::string& name) const {
  const auto it = impl_->response.find(name);
  return it == impl_->response.end() ? std::string() : std::string(it->value());
}

std::optional<WsClient::Message> WsClient::read(std::chrono::milliseconds timeout) {
  Impl& c = *impl_;
  if (!c.read_pending) {
    c.buffer.clear();
    c.read_done = false;
    c.read_pending = true;
    c.ws.async_read(c.buffer, [&c](const error_code& e, std::size_t) {
      c.read_ec = e;
      c.read_done = true;
    });
  }
  if (!c.run_until(c.read_done, timeout)) return std::nullopt;  // still pending
  c.read_pending = false;
  if (c.read_ec) return std::nullopt;
  return Message{c.ws.got_text(), beast::buffers_to_string(c.buffer.data())};
}

nlohmann::json WsClient::read_json() {
  for (int i = 0; i < 100000; ++i) {
    auto m = read();
    if (!m) return nlohmann::json();
    if (m->text) return nlohmann::json::parse(m->data);
  }
  return nlohmann::json();
}

nlohmann::json WsClient::read_status(const std::string& id) {
  for (int i = 0; i < 100000; ++i) {
    nlohmann::json j = read_json();
    if (j.is_null()) return j;
    if (j.value("op", "") == "status" && j.value("id", "") == id) return j;
  }
  return nlohmann::json();
}

bool WsClient::send(const std::string& data, bool binary) {
  Impl& c = *impl_;
  c.ws.binary(binary);
  bool done = false;
  error_code ec;
  c.ws.async_write(net::buffer(data), [&](const error_code& e, std::size_t) {
    ec = e;
    done = true;
  });
  if (!c.run_until(done)) {
    c.abandon();
    return false;
  }
  return !ec;
}

bool WsClient::sync() {
  return send_json({{"op", "unsubscribe"}, {"subscriptionIds", {4000000000u}}}) &&
         !read_status("unknown-subscription").is_null();
}

void WsClient::close() {
  bool done = false;
  impl_->ws.async_close(websocket::close_code::normal, [&](const error_code&) { done = true; });
  if (!impl_->run_until(done, 1000ms)) impl_->abandon();
}

std::string HttpResult::header(const std::string& name) const {
  const auto it = headers.find(lower(name));
  return it == headers.end() ? std::string() : it->second;
}

HttpResult http_request(std::uint16_t port, const std::string& method, const std::string& target,
                        const std::string& extra_header) {
  net::io_context ioc;
  beast::tcp_stream stream(ioc);
  http::response<http::string_body> res;
  res.result(http::status::unknown);
  stream.expires_after(kExchangeTimeout);
  http::request<http::string_body> req(http::string_to_verb(method), target, 11);
  req.set(http::field::host, "127.0.0.1");
  if (!extra_header.empty()) req.set("X-Filler", extra_header);
  if (req.method() == http::verb::post) {
    req.body() = "x=1";
    req.prepare_payload();
  }
  http::response_parser<http::string_body> parser;
  parser.body_limit(1ull << 30);
  parser.skip(req.method() == http::verb::head);
  beast::flat_buffer buf;
  bool answered = false;
  stream.async_connect(tcp::endpoint(net::ip::address_v4::loopback(), port), [&](const error_code& ec) {
    if (ec) return;
    http::async_write(stream, req, [&](const error_code& ec2, std::size_t) {
      if (ec2) return;
      http::async_read(stream, buf, parser, [&](const error_code& ec3, std::size_t) { answered = !ec3; });
    });
  });
  ioc.run_for(kExchangeTimeout);
  HttpResult r;
  if (!answered) return r;
  const auto& m = parser.get();
  r.status = m.result_int();
  r.body = m.body();
  for (const auto& f : m) r.headers[lower(std::string(f.name_string()))] = std::string(f.value());
  return r;
}

}  // namespace mc::test

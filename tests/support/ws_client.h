#pragma once
/// @file
/// A small Foxglove WebSocket and HTTP client over loopback for the server tests (Boost.Beast
/// stays in ws_client.cc). Every operation runs under a deadline, so a broken server fails the
/// test instead of hanging it.

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace mc::test {

/// How long a read waits for a message by default.
inline constexpr std::chrono::milliseconds kClientTimeout{5000};
/// How long a connection, an upgrade or an HTTP exchange may take: long, because a server that
/// answers at all is what the tests assert, and a sanitized build on a loaded machine answers
/// slowly (a refused or answered request comes back at once anyway).
inline constexpr std::chrono::milliseconds kExchangeTimeout{30000};

class WsClient {
 public:
  WsClient();
  ~WsClient();
  WsClient(const WsClient&) = delete;
  WsClient& operator=(const WsClient&) = delete;

  /// Connects and upgrades; returns the HTTP status of the upgrade (101 when accepted, -1 when
  /// no answer came).
  int connect(std::uint16_t port, const std::string& target = "/", bool subprotocol = true);
  /// A header of the upgrade's answer ("" when absent).
  std::string response_header(const std::string& name) const;

  struct Message {
    bool text = false;
    std::string data;
  };
  /// The next message, or nullopt on error/timeout (then the client is unusable).
  std::optional<Message> read(std::chrono::milliseconds timeout = kClientTimeout);
  /// The next text message as JSON (binary messages before it are skipped); null on timeout.
  nlohmann::json read_json();
  /// Reads until a status with this id arrives (other messages skipped); null on timeout.
  nlohmann::json read_status(const std::string& id);

  bool send(const std::string& data, bool binary = false);
  bool send_json(const nlohmann::json& j) { return send(j.dump()); }
  /// Sends an op the server answers with an error, and waits for that answer: every message sent
  /// before it has then been handled (the server handles a client's messages in order).
  bool sync();
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct HttpResult {
  int status = -1;  ///< -1: no answer
  std::string body;
  std::map<std::string, std::string> headers;  ///< names in lower case
  std::string header(const std::string& name) const;
};

/// One HTTP request (`method` GET, HEAD, POST...) on a fresh connection; `extra_header` fills an
/// X-Filler header (oversized-header tests).
HttpResult http_request(std::uint16_t port, const std::string& method, const std::string& target,
                        const std::string& extra_header = "");

}  // namespace mc::test

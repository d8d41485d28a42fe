#pragma once
/// @file
/// The controller end of a vendor driver (issue #30): `devices.connection` parsed, and a blocking
/// TCP client with a deadline on every operation, owned by the driver's bus thread (never the
/// loop). A serial path (/dev/ttyUSB0) is refused: no termios transport is written yet.
///
///     devices: {driver: pi-gcs2, connection: "127.0.0.1:50000,timeout_s=0.2"}
///
/// The connection is `HOST:PORT` then optional `,key=value` options of the driver (each driver
/// names the keys it takes and refuses the others).

#include <chrono>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>

namespace mc::vendor {

struct Connection {
  std::string host;
  std::uint16_t port = 0;
  std::map<std::string, std::string> options;  ///< the `,key=value` options, in order of keys
};

/// Parses `text` for `driver` (named in the errors). Throws mc::InvalidParams naming
/// devices.connection and what was given: a serial path ("serial is not supported yet"), no
/// port, a port out of 1..65535, an option without '=' or given twice.
Connection parse_connection(const std::string& text, std::string_view driver);

/// The option `key` as a number within [lo, hi], else `fallback`; throws mc::InvalidParams naming
/// devices.connection's option when it is not one.
double connection_number(const Connection& c, const std::string& key, double fallback, double lo, double hi);

/// Refuses (mc::InvalidParams) any option not in `known` (a comma-separated list, for the message).
void check_connection_options(const Connection& c, std::string_view known);

class LineClient {
 public:
  using Clock = std::chrono::steady_clock;
  LineClient() = default;
  ~LineClient() { close(); }
  LineClient(const LineClient&) = delete;
  LineClient& operator=(const LineClient&) = delete;

  /// Connects within `timeout_s` (IPv4/IPv6 by getaddrinfo). Throws mc::InvalidInput naming the
  /// address and the system's reason.
  void connect(const std::string& host, std::uint16_t port, double timeout_s);
  bool is_open() const { return fd_ >= 0; }
  void close() noexcept;

  /// Sends every byte before `deadline`; false on a timeout or a broken connection (`error()`).
  bool send(std::string_view bytes, Clock::time_point deadline);
  /// Reads into `text` (appended) until `complete(text)` holds; false on a timeout, EOF or an
  /// error (`error()` says which). Bytes past the reply stay buffered for the next read.
  template <class Complete>
  bool read_until(std::string& text, Complete&& complete, Clock::time_point deadline) {
    while (true) {
      if (!pending_.empty()) {
        text += pending_;
        pending_.clear();
      }
      if (const std::size_t end = complete(text); end != 0) {
        pending_.assign(text, end, std::string::npos);  // what came after the reply
        text.resize(end);
        return true;
      }
      if (!read_some(deadline)) return false;
    }
  }
  /// Drops what arrived unasked (buffered or readable now, without waiting).
  void discard_input();
  const std::string& error() const { return error_; }

 private:
  bool read_some(Clock::time_point deadline);
  int fd_ = -1;
  std::string pending_;
  std::string error_;
};

}  // namespace mc::vendor

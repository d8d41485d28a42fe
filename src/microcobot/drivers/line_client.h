#pragma once
/// @file
/// The controller end of a vendor driver: `devices.connection` parsed, and a blocking
/// line client with a deadline on every operation (poll()), owned by the driver's bus thread
/// (never the loop), over TCP or a serial line (termios: raw, 8N1, no flow control unless asked).
///
///     devices: {driver: pi-gcs2, connection: "127.0.0.1:50000,timeout_s=0.2"}
///     devices: {driver: pi-gcs2, connection: "/dev/ttyUSB0,baud=115200"}
///
/// The connection is `HOST:PORT` or an absolute device path, then optional `,key=value` options:
/// the serial line's own (`baud`, `flow`, taken here and refused on TCP) and the driver's (each
/// driver names the keys it takes and refuses the others).

#include <chrono>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>

namespace mc::drivers {

/// A serial line's settings (8N1 always: every controller here speaks it).
struct SerialLine {
  std::string path;     ///< the device (/dev/ttyUSB0, /dev/ttyS0, /dev/serial/by-id/...)
  int baud = 0;         ///< one of kSerialBauds
  bool rtscts = false;  ///< hardware flow control (`flow=rtscts`); none by default
};

/// The rates a serial line accepts (the POSIX/Linux termios speeds a USB adapter offers).
inline constexpr int kSerialBauds[] = {1200,  2400,   4800,   9600,   19200, 38400,
                                       57600, 115200, 230400, 460800, 921600};

struct Connection {
  std::string host;  ///< TCP: the host (empty for a serial line)
  std::uint16_t port = 0;
  SerialLine serial;                           ///< a serial line when serial.path is not empty
  std::map<std::string, std::string> options;  ///< the driver's `,key=value` options, in order of keys
  bool is_serial() const { return !serial.path.empty(); }
  /// What the errors name: HOST:PORT or the device path.
  std::string where() const;
};

/// Parses `text` for `driver` (named in the errors); a serial line runs at `default_baud` unless
/// `baud=` says otherwise (the drivers pass their controller's factory rate). Throws
/// mc::InvalidParams naming devices.connection and what was given: a Windows port name (COM3), a
/// relative path, no port, a port out of 1..65535, an option without '=' or given twice, a baud
/// not in kSerialBauds, a flow other than none|rtscts, baud/flow on a TCP connection.
Connection parse_connection(const std::string& text, std::string_view driver, int default_baud = 115200);

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
  /// Opens a serial line (serial_line.cc): raw, 8N1, `line.baud`, no flow control unless
  /// `line.rtscts`, exclusive (TIOCEXCL), input and output flushed. Throws mc::InvalidInput naming
  /// the path: it does not exist, cannot be opened, is not a tty, or refuses the settings.
  void open_serial(const SerialLine& line);
  /// Either of the above, as `c` says.
  void open(const Connection& c, double timeout_s);
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
  bool tty_ = false;  // a serial line: read()/write() (send()/recv() are sockets' only)
  std::string pending_;
  std::string error_;
};

}  // namespace mc::drivers

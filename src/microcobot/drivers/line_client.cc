#include "microcobot/drivers/line_client.h"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <iterator>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/drivers/gcs2_codec.h"

namespace mc::drivers {
namespace {

constexpr const char* kField = "devices.connection";

int remaining_ms(LineClient::Clock::time_point deadline) {
  const auto left =
      std::chrono::duration_cast<std::chrono::milliseconds>(deadline - LineClient::Clock::now());
  return left.count() <= 0 ? 0 : static_cast<int>(std::min<long long>(left.count() + 1, 1 << 30));
}

}  // namespace

std::string Connection::where() const {
  return is_serial() ? serial.path : host + ":" + std::to_string(port);
}

namespace {

// The serial line's own options, taken out of `c.options` (the driver never sees them).
void take_serial_options(Connection& c, const std::string& text, int default_baud) {
  c.serial.baud = default_baud;
  if (const auto it = c.options.find("baud"); it != c.options.end()) {
    const auto v = gcs2::parse_number(it->second);
    const bool known =
        v && std::find(std::begin(kSerialBauds), std::end(kSerialBauds), *v) != std::end(kSerialBauds);
    if (!known)
      throw InvalidParams(
          std::string(kField) + " option baud",
          "'" + excerpt(it->second) +
              "' must be one of 1200 2400 4800 9600 19200 38400 57600 115200 230400 460800 921600");
    c.serial.baud = static_cast<int>(*v);
    c.options.erase(it);
  }
  if (const auto it = c.options.find("flow"); it != c.options.end()) {
    if (it->second != "none" && it->second != "rtscts")
      throw InvalidParams(std::string(kField) + " option flow",
                          "'" + excerpt(it->second) + "' must be none or rtscts (" + excerpt(text) + ")");
    c.serial.rtscts = it->second == "rtscts";
    c.options.erase(it);
  }
}

}  // namespace

Connection parse_connection(const std::string& text, std::string_view driver, int default_baud) {
  const std::string d(driver);
  if (text.rfind("COM", 0) == 0)
    throw InvalidParams(kField, "'" + excerpt(text) + "': a Windows port name; the " + d +
                                    " driver takes a device path (/dev/ttyUSB0, /dev/ttyS0) or HOST:PORT");
  Connection c;
  std::string_view rest(text);
  const auto comma = rest.find(',');
  const std::string_view address = rest.substr(0, comma);
  const bool serial = !address.empty() && address.front() == '/';
  if (serial) {
    c.serial.path = std::string(address);
  } else {
    const auto colon = address.rfind(':');
    if (address.empty() || colon == std::string_view::npos || colon == 0 || colon + 1 == address.size())
      throw InvalidParams(kField, "'" + excerpt(text) + "': the " + d +
                                      " driver needs HOST:PORT (e.g. 127.0.0.1:50000) or a device path "
                                      "(/dev/ttyUSB0)");
    std::string host(address.substr(0, colon));
    if (host.size() > 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
    const std::string_view port = address.substr(colon + 1);
    const auto number = gcs2::parse_number(port);
    if (port.size() > 5 || port.find_first_not_of("0123456789") != std::string_view::npos || !number ||
        *number < 1 || *number > 65535)
      throw InvalidParams(kField, "'" + excerpt(text) + "': the port must be 1 to 65535");
    c.host = host;
    c.port = static_cast<std::uint16_t>(*number);
  }
  while (comma != std::string_view::npos && !rest.empty()) {
    rest = rest.substr(rest.find(',') + 1);
    const auto next = rest.find(',');
    const std::string_view item = rest.substr(0, next);
    const auto eq = item.find('=');
    if (eq == std::string_view::npos || eq == 0)
      throw InvalidParams(kField,
                          "'" + excerpt(text) + "': option '" + excerpt(item) + "' must be KEY=VALUE");
    if (!c.options.emplace(std::string(item.substr(0, eq)), std::string(item.substr(eq + 1))).second)
      throw InvalidParams(
          kField, "'" + excerpt(text) + "': option '" + excerpt(item.substr(0, eq)) + "' given twice");
    if (next == std::string_view::npos) break;
  }
  if (serial) {
    take_serial_options(c, text, default_baud);
  } else {
    for (const char* key : {"baud", "flow"})
      if (c.options.count(key) != 0)
        throw InvalidParams(kField, "'" + excerpt(text) + "': option '" + key +
                                        "' is a serial line's; this connection is TCP (HOST:PORT)");
  }
  return c;
}

double connection_number(const Connection& c, const std::string& key, double fallback, double lo, double hi) {
  const auto it = c.options.find(key);
  if (it == c.options.end()) return fallback;
  const auto v = gcs2::parse_number(it->second);
  if (!v || *v < lo || *v > hi)
    throw InvalidParams(
        std::string(kField) + " option " + key,
        "'" + excerpt(it->second) + "' must be a number within " + fmt::format("[{:g}, {:g}]", lo, hi));
  return *v;
}

void check_connection_options(const Connection& c, std::string_view known) {
  for (const auto& [key, value] : c.options) {
    bool ok = false;
    std::string_view list = known;
    while (!list.empty()) {
      const auto comma = list.find(',');
      std::string_view k = list.substr(0, comma);
      while (!k.empty() && k.front() == ' ') k.remove_prefix(1);
      if (k == key) ok = true;
      if (comma == std::string_view::npos) break;
      list.remove_prefix(comma + 1);
    }
    if (!ok)
      throw InvalidParams(kField,
                          "unknown option '" + excerpt(key) + "' (known: " + std::string(known) + ")");
  }
}

void LineClient::connect(const std::string& host, std::uint16_t port, double timeout_s) {
  close();
  const std::string where = host + ":" + std::to_string(port);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (const int rc = ::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found); rc != 0)
    throw InvalidInput("cannot resolve the controller's address " + excerpt(where) + ": " + gai_strerror(rc));
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  std::string reason = "no address";
  for (addrinfo* a = found; a != nullptr; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    int rc = ::connect(fd, a->ai_addr, a->ai_addrlen);
    if (rc != 0 && errno == EINPROGRESS) {
      pollfd p{fd, POLLOUT, 0};
      rc = ::poll(&p, 1, remaining_ms(deadline));
      if (rc == 1) {
        int err = 0;
        socklen_t len = sizeof err;
        ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len);
        rc = err == 0 ? 0 : -1;
        if (err != 0) reason = std::strerror(err);
      } else {
        reason = rc == 0 ? "timed out" : std::strerror(errno);
        rc = -1;
      }
    } else if (rc != 0) {
      reason = std::strerror(errno);
    }
    if (rc == 0) {
      int one = 1;
      ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);  // one short line per request
      fd_ = fd;
      break;
    }
    ::close(fd);
  }
  ::freeaddrinfo(found);
  if (fd_ < 0) throw InvalidInput("cannot connect to the controller at " + excerpt(where) + ": " + reason);
  pending_.clear();
  error_.clear();
}

void LineClient::open(const Connection& c, double timeout_s) {
  if (c.is_serial())
    open_serial(c.serial);
  else
    connect(c.host, c.port, timeout_s);
}

void LineClient::close() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  tty_ = false;
  pending_.clear();
}

bool LineClient::send(std::string_view bytes, Clock::time_point deadline) {
  if (fd_ < 0) return error_ = "not connected", false;
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = tty_ ? ::write(fd_, bytes.data() + done, bytes.size() - done)
                           : ::send(fd_, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      pollfd p{fd_, POLLOUT, 0};
      if (::poll(&p, 1, remaining_ms(deadline)) <= 0) return error_ = "send timed out", false;
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    return error_ = std::string("connection lost (") + std::strerror(errno) + ")", false;
  }
  return true;
}

bool LineClient::read_some(Clock::time_point deadline) {
  if (fd_ < 0) return error_ = "not connected", false;
  char buf[4096];
  while (true) {
    const ssize_t n = tty_ ? ::read(fd_, buf, sizeof buf) : ::recv(fd_, buf, sizeof buf, 0);
    if (n > 0) {
      pending_.append(buf, static_cast<std::size_t>(n));
      return true;
    }
    // A tty reads 0 (VMIN=1, O_NONBLOCK) only once hung up: a closed pty master does that
    // (serial_line_test.cc); a device that went away may fail with an error (EIO) instead, which
    // lands below as "connection lost". Either faults the bus.
    if (n == 0)
      return error_ = tty_ ? "the serial line hung up" : "the controller closed the connection", false;
    if (errno == EINTR) continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK)
      return error_ = std::string("connection lost (") + std::strerror(errno) + ")", false;
    pollfd p{fd_, POLLIN, 0};
    const int rc = ::poll(&p, 1, remaining_ms(deadline));
    if (rc == 0) return error_ = "no reply within the timeout", false;
    if (rc < 0 && errno != EINTR) return error_ = std::string("poll: ") + std::strerror(errno), false;
  }
}

void LineClient::discard_input() {
  pending_.clear();
  if (fd_ < 0) return;
  char buf[4096];
  if (tty_) {
    while (::read(fd_, buf, sizeof buf) > 0) {  // O_NONBLOCK: never waits
    }
    return;
  }
  while (::recv(fd_, buf, sizeof buf, MSG_DONTWAIT) > 0) {
  }
}

}  // namespace mc::drivers

#pragma once
/// @file
/// A scriptable controller on loopback (port 0) for the vendor drivers' fault tests:
/// one connection at a time, every line handed to the test's `answer` (what to send back, or to
/// close, or to say nothing), every line received kept. The thread polls, so that stop() returns
/// at once whatever the client does.
///
/// With Transport::kPty the controller sits on the master of a pseudo-terminal instead and the
/// driver opens its slave (`tty_path()`) as it would /dev/ttyUSB0: the serial transport's stand-in
/// (no USB adapter is involved). Closing (`Answer::close`) closes the master: the line is unplugged
/// for good (the slave reads EIO, its path disappears).

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace mc::test {

class FakeController {
 public:
  struct Answer {
    std::string bytes;   ///< sent back as is (may be an unterminated line)
    bool close = false;  ///< then the connection is closed (a controller that goes away)
  };
  /// `answer(line)` runs on the server's thread; `greeting` is sent on each connection;
  /// `eol` ends the lines ("\n" for GCS, "\r\n" for the ANC300: CR is stripped either way).
  enum class Transport { kTcp, kPty };
  FakeController(std::function<Answer(const std::string&)> answer, std::string greeting = {},
                 Transport transport = Transport::kTcp)
      : answer_(std::move(answer)), greeting_(std::move(greeting)), pty_(transport == Transport::kPty) {
    if (pty_) {
      master_fd_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
      if (master_fd_ < 0 || ::grantpt(master_fd_) != 0 || ::unlockpt(master_fd_) != 0)
        throw std::runtime_error("fake controller: no pseudo-terminal");
      char name[128];
      if (::ptsname_r(master_fd_, name, sizeof name) != 0)
        throw std::runtime_error("fake controller: ptsname");
      tty_path_ = name;
      thread_ = std::thread([this] { run_pty(); });
      return;
    }
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    int one = 1;
    ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 || ::listen(listen_fd_, 4) != 0)
      throw std::runtime_error("fake controller: cannot listen");
    socklen_t len = sizeof a;
    ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { run(); });
  }
  ~FakeController() {
    stop_ = true;
    thread_.join();
    if (listen_fd_ >= 0) ::close(listen_fd_);
    if (master_fd_ >= 0) ::close(master_fd_);
  }
  std::uint16_t port() const { return port_; }
  /// The slave's path (Transport::kPty): what the driver's connection names.
  const std::string& tty_path() const { return tty_path_; }
  /// The line unplugged (Transport::kPty: the master was closed).
  bool unplugged() const { return unplugged_.load(); }
  std::vector<std::string> lines() const {
    std::lock_guard lock(mutex_);
    return lines_;
  }
  /// How many received lines start with `prefix`.
  int count(const std::string& prefix) const {
    std::lock_guard lock(mutex_);
    int n = 0;
    for (const auto& l : lines_) n += l.rfind(prefix, 0) == 0 ? 1 : 0;
    return n;
  }
  int connections() const { return connections_.load(); }

 private:
  void run() {
    while (!stop_) {
      pollfd p{listen_fd_, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
      if (fd < 0) continue;
      ++connections_;
      serve(fd);
      ::close(fd);
    }
  }
  // The master end: a session per opening of the slave (the master reads EIO while none is open).
  void run_pty() {
    while (!stop_ && master_fd_ >= 0) {
      if (serve(master_fd_)) {
        // Said before the close: the client sees the hang-up as soon as the master closes.
        unplugged_ = true;
        ::close(master_fd_);
        master_fd_ = -1;
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  void put(int fd, const std::string& bytes) {
    if (pty_)
      (void)!::write(fd, bytes.data(), bytes.size());
    else
      ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
  }
  // True when the answer closed the connection (or unplugged the line).
  bool serve(int fd) {
    if (!greeting_.empty()) put(fd, greeting_);
    std::string buffer;
    char buf[4096];
    while (!stop_) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      const ssize_t n = pty_ ? ::read(fd, buf, sizeof buf) : ::recv(fd, buf, sizeof buf, 0);
      if (n <= 0) return false;
      buffer.append(buf, static_cast<std::size_t>(n));
      std::size_t eol;
      while ((eol = buffer.find('\n')) != std::string::npos) {
        std::string line = buffer.substr(0, eol);
        buffer.erase(0, eol + 1);
        if (!line.empty() && line.back() == '\r') line.pop_back();
        {
          std::lock_guard lock(mutex_);
          lines_.push_back(line);
        }
        const Answer a = answer_(line);
        if (!a.bytes.empty()) put(fd, a.bytes);
        if (a.close) return true;
      }
    }
    return false;
  }

  std::function<Answer(const std::string&)> answer_;
  std::string greeting_;
  bool pty_ = false;
  int listen_fd_ = -1, master_fd_ = -1;
  std::string tty_path_;
  std::atomic<bool> unplugged_{false};
  std::uint16_t port_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<int> connections_{0};
  mutable std::mutex mutex_;
  std::vector<std::string> lines_;
  std::thread thread_;
};

}  // namespace mc::test

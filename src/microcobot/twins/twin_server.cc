#include "microcobot/twins/twin_server.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <deque>
#include <map>
#include <mutex>
#include <thread>

#include <boost/asio.hpp>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"

namespace mc::twins {

namespace asio = boost::asio;
using asio::ip::tcp;
using Clock = std::chrono::steady_clock;

namespace {

bool loopback_address(const std::string& host) {
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

}  // namespace

const char* protocol_name(Protocol p) {
  switch (p) {
    case Protocol::kGcs2:
      return "gcs2";
    case Protocol::kAnc300:
      return "anc300";
    case Protocol::kMcs2:
      return "mcs2";
    case Protocol::kGcs2Hexapod:
      return "gcs2-hexapod";
  }
  return "?";
}

TwinEndpoint parse_emulate(const std::string& whole) {
  TwinEndpoint e;
  std::string text = whole;
  if (const auto comma = whole.find(','); comma != std::string::npos) {
    text = whole.substr(0, comma);
    const std::string option = whole.substr(comma + 1);
    const std::string key = "no_sensor=";
    bool ok = text.rfind("mcs2", 0) == 0 && option.rfind(key, 0) == 0 && option.size() > key.size() &&
              (option.size() - key.size()) % 2 == 1;  // N, N+M, N+M+K
    for (std::size_t k = key.size(); ok && k < option.size(); k += 2) {
      ok = option[k] >= '0' && option[k] <= '3' && (k + 1 == option.size() || option[k + 1] == '+');
      if (ok) e.no_sensor_channels |= 1u << (option[k] - '0');
    }
    if (!ok)
      throw UsageError("--emulate: '" + excerpt(whole) +
                       "': the one option is mcs2's no_sensor=N[+M...] (channels 0..3 without a sensor)");
  }
  const auto eq = text.find('=');
  const std::string name = text.substr(0, eq);
  if (name == "gcs2") {
    e.protocol = Protocol::kGcs2;
    e.port = 50000;
  } else if (name == "anc300") {
    e.protocol = Protocol::kAnc300;
    e.port = 7230;
  } else if (name == "mcs2") {
    e.protocol = Protocol::kMcs2;
    e.port = drivers::mcs2::kDefaultPort;
  } else if (name == "gcs2-hexapod") {
    e.protocol = Protocol::kGcs2Hexapod;
    e.port = 50000;  // the C-887's TCP port, as every GCS controller's
  } else {
    throw UsageError("--emulate: '" + excerpt(text) +
                     "' must be gcs2[=ADDR:PORT], anc300[=ADDR:PORT], mcs2[=ADDR:PORT] or "
                     "gcs2-hexapod[=ADDR:PORT]");
  }
  if (eq == std::string::npos) return e;
  const std::string where = text.substr(eq + 1);
  const auto colon = where.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == where.size())
    throw UsageError("--emulate: '" + excerpt(text) +
                     "': the address must be ADDR:PORT (e.g. 127.0.0.1:50000)");
  std::string host = where.substr(0, colon);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  const std::string port = where.substr(colon + 1);
  if (port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos ||
      std::stoul(port) > 65535)
    throw UsageError("--emulate: '" + excerpt(text) + "': port '" + excerpt(port) +
                     "' must be within [0, 65535]");
  e.address = host;
  e.port = static_cast<std::uint16_t>(std::stoul(port));
  return e;
}

void TwinServerParams::validate() const {
  require(!endpoints.empty(), "twin.endpoints", "must name at least one protocol");
  bool off_loopback = false;
  for (const auto& e : endpoints) off_loopback |= !loopback_address(e.address);
  require(!off_loopback || (token.size() >= 8 && token.size() <= 256), "twin.token",
          "is required off loopback (8 to 256 characters)");
  require(max_clients >= 1 && max_clients <= 1024, "twin.max_clients", "must be within [1, 1024]",
          static_cast<double>(max_clients));
  require(std::isfinite(line_timeout_s) && line_timeout_s > 0, "twin.line_timeout_s", "must be > 0",
          line_timeout_s);
  require(std::isfinite(login_timeout_s) && login_timeout_s > 0, "twin.login_timeout_s", "must be > 0",
          login_timeout_s);
  require(max_output_bytes >= 1024, "twin.max_output_bytes", "must be at least 1024",
          static_cast<double>(max_output_bytes));
  require(std::isfinite(heartbeat_s) && heartbeat_s > 0 && heartbeat_s <= 0.1, "twin.heartbeat_s",
          "must be within (0, 0.1] s", heartbeat_s);
  gcs2.validate();
  anc300.validate();
  mcs2.validate();
  gcs2_hexapod.validate();
}

struct TwinServer::Impl {
  struct Session : std::enable_shared_from_this<Session> {
    Session(Impl& s, tcp::socket sock, Protocol p, ClientId i, bool tokened)
        : srv(s), socket(std::move(sock)), protocol(p), id(i), needs_token(tokened) {}
    Impl& srv;
    tcp::socket socket;
    Protocol protocol;
    ClientId id;
    bool needs_token;  // off loopback: the GCS or MCS2 client's first line, the ANC300 password
    bool authorized = false;
    Anc300Session anc;
    std::array<char, 4096> buffer{};
    std::string line, unprocessed;
    bool overlong = false;
    Clock::time_point partial_since{}, opened = Clock::now();
    std::deque<std::string> out;
    std::size_t out_bytes = 0;
    bool writing = false, reading_done = false, closing = false, closed = false;
    int waiting_axis = -1;  // an ANC300 stepw in progress
    int failed_logins = 0;
  };

  Impl(TwinStage& st, TwinServerParams p)
      : stage(st),
        params(std::move(p)),
        gcs2(st, params.gcs2),
        anc300(st, params.anc300),
        mcs2(st, params.mcs2),
        timer(io) {
    for (const auto& e : params.endpoints)
      if (e.protocol == Protocol::kGcs2Hexapod && !hexapod)
        hexapod = std::make_unique<Gcs2HexapodTwin>(st, params.gcs2_hexapod);
  }

  TwinStage& stage;
  TwinServerParams params;
  Gcs2Twin gcs2;
  Anc300Twin anc300;
  Mcs2Twin mcs2;
  std::unique_ptr<Gcs2HexapodTwin> hexapod;  // with the hexapod twin only
  asio::io_context io;
  std::vector<std::unique_ptr<tcp::acceptor>> acceptors;
  std::vector<Protocol> acceptor_protocols;
  std::vector<bool> acceptor_tokened;
  std::vector<std::uint16_t> bound;
  std::map<ClientId, std::shared_ptr<Session>> sessions;
  asio::steady_timer timer;
  Clock::time_point last_round = Clock::now();  // the housekeeping's last round
  ClientId next_id = 1;
  std::thread thread;
  std::atomic<bool> running{false};
  mutable std::mutex counters_mutex;  // the protocol thread and counters() readers; never the loop
  TwinServerCounters counts;

  void count(std::uint64_t TwinServerCounters::*field) {
    std::lock_guard lock(counters_mutex);
    ++(counts.*field);
  }

  void accept(std::size_t k) {
    acceptors[k]->async_accept([this, k](boost::system::error_code ec, tcp::socket sock) {
      if (ec == asio::error::operation_aborted) return;
      if (!ec) on_accept(k, std::move(sock));
      accept(k);
    });
  }

  void on_accept(std::size_t k, tcp::socket sock) {
    if (sessions.size() >= params.max_clients) {
      count(&TwinServerCounters::refused);
      boost::system::error_code ignored;
      sock.close(ignored);
      return;
    }
    boost::system::error_code ec;
    sock.set_option(tcp::no_delay(true), ec);
    count(&TwinServerCounters::accepted);
    auto s = std::make_shared<Session>(*this, std::move(sock), acceptor_protocols[k], next_id++,
                                       acceptor_tokened[k]);
    sessions[s->id] = s;
    if (s->protocol == Protocol::kAnc300) {
      send(*s, anc300.greeting());
    } else {
      s->authorized = !s->needs_token;
    }
    read(s);
  }

  void read(const std::shared_ptr<Session>& s) {
    if (s->closed || s->reading_done) return;
    s->socket.async_read_some(asio::buffer(s->buffer),
                              [this, s](boost::system::error_code ec, std::size_t n) {
                                if (s->closed) return;
                                if (ec) {
                                  // EOF (a half-closed socket) or an error: what was asked is answered, then
                                  // closed.
                                  s->reading_done = true;
                                  flush_then_close(*s);
                                  return;
                                }
                                s->unprocessed.append(s->buffer.data(), n);
                                process(*s);
                                if (!s->closed && s->waiting_axis < 0) read(s);
                              });
  }

  void flush_then_close(Session& s) {
    if (s.out.empty() && !s.writing) {
      close(s);
    } else {
      s.closing = true;
    }
  }

  void close(Session& s) {
    if (s.closed) return;
    s.closed = true;
    boost::system::error_code ignored;
    s.socket.shutdown(tcp::socket::shutdown_both, ignored);
    s.socket.close(ignored);
    // Gone: if it controlled the stage, the stage holds.
    if (s.protocol == Protocol::kGcs2)
      gcs2.on_disconnect(s.id);
    else if (s.protocol == Protocol::kGcs2Hexapod)
      hexapod->on_disconnect(s.id);
    else if (s.protocol == Protocol::kMcs2)
      mcs2.on_disconnect(s.id);
    else
      anc300.on_disconnect(s.id);
    sessions.erase(s.id);
  }

  void hostile(Session& s) {
    count(&TwinServerCounters::closed_hostile);
    close(s);
  }

  void send(Session& s, std::string bytes) {
    if (s.closed || bytes.empty()) return;
    s.out_bytes += bytes.size();
    if (s.out_bytes > params.max_output_bytes) return hostile(s);  // it does not read its replies
    s.out.push_back(std::move(bytes));
    if (!s.writing) write(s.shared_from_this());
  }

  void write(const std::shared_ptr<Session>& s) {
    s->writing = true;
    asio::async_write(s->socket, asio::buffer(s->out.front()),
                      [this, s](boost::system::error_code ec, std::size_t) {
                        s->writing = false;
                        if (s->closed) return;
                        if (ec) return close(*s);
                        s->out_bytes -= s->out.front().size();
                        s->out.pop_front();
                        if (!s->out.empty()) return write(s);
                        if (s->closing) close(*s);
                      });
  }

  /// Consumes the received bytes, line by line, until a stepw waits or they run out.
  void process(Session& s) {
    std::size_t i = 0;
    for (; i < s.unprocessed.size() && !s.closed && s.waiting_axis < 0; ++i) {
      const char c = s.unprocessed[i];
      const bool gcs = s.protocol == Protocol::kGcs2 || s.protocol == Protocol::kGcs2Hexapod;
      if (gcs && s.authorized &&
          (c == drivers::gcs2::kMotionStatus || c == drivers::gcs2::kReadyStatus ||
           c == drivers::gcs2::kStopAll)) {
        send(s, s.protocol == Protocol::kGcs2 ? gcs2.on_byte(s.id, c) : hexapod->on_byte(s.id, c));
        continue;
      }
      if (c == '\n') {
        std::string line = std::move(s.line);
        s.line.clear();
        const bool overlong = s.overlong;
        s.overlong = false;
        on_line(s, line, overlong);
        continue;
      }
      if (c == '\0') continue;  // telnet's CR NUL
      if (s.line.empty()) s.partial_since = Clock::now();
      const std::size_t cap = gcs                             ? drivers::gcs2::kMaxLineLength
                              : s.protocol == Protocol::kMcs2 ? drivers::mcs2::kMaxLineLength
                                                              : drivers::anc300::kMaxLineLength;
      if (s.line.size() < cap) {
        s.line += c;
      } else {
        s.overlong = true;  // the rest of the line is discarded
      }
    }
    s.unprocessed.erase(0, i);
  }

  void on_line(Session& s, std::string& line, bool overlong) {
    count(&TwinServerCounters::lines);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (s.protocol != Protocol::kAnc300) {
      if (!s.authorized) {
        // Off loopback the first line is the token; anything else closes the connection.
        if (line != params.token) return hostile(s);
        s.authorized = true;
        return;
      }
      if (s.protocol == Protocol::kMcs2) {
        if (overlong) return mcs2.on_overlong_line();
        return send(s, mcs2.on_line(s.id, line));
      }
      if (s.protocol == Protocol::kGcs2Hexapod) {
        if (overlong) return hexapod->on_overlong_line();
        return send(s, hexapod->on_line(s.id, line));
      }
      if (overlong) return gcs2.on_overlong_line();
      return send(s, gcs2.on_line(s.id, line));
    }
    if (!s.anc.authorized) {
      const bool ok = (!params.token.empty() && line == params.token) ||
                      (!s.needs_token && line == drivers::anc300::kFactoryPassword);
      send(s, anc300.on_password(s.anc, line, ok));
      // A wrong password is asked again (pymeasure reads the failure before it gives up); the
      // third closes the connection.
      if (!ok && ++s.failed_logins >= 3) flush_then_close(s);
      return;
    }
    if (overlong) return send(s, anc300.on_overlong_line(s.anc));
    auto reply = anc300.on_line(s.id, s.anc, line);
    if (reply) return send(s, std::move(*reply));
    s.waiting_axis = anc300.waiting_axis();  // stepw: answered by the housekeeping once it stops
  }

  void housekeeping() {
    stage.heartbeat();
    const auto now = Clock::now();
    const auto heartbeat =
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(params.heartbeat_s));
    // A round that comes late (this thread starved of the CPU: a loaded machine, a sanitizer)
    // judges no timeout: what the clients sent meanwhile may wait unread in the kernel or in the
    // queue behind this handler, and the late one is the server, not the client. The next round,
    // on time, judges with it read.
    const bool on_time = now - last_round <= 5 * heartbeat;
    last_round = now;
    const auto line_timeout = std::chrono::duration<double>(params.line_timeout_s);
    const auto login_timeout = std::chrono::duration<double>(params.login_timeout_s);
    std::vector<std::shared_ptr<Session>> all;
    for (auto& [id, s] : sessions) all.push_back(s);
    for (auto& s : all) {
      if (s->closed) continue;
      if (on_time && !s->line.empty() && now - s->partial_since > line_timeout) {
        hostile(*s);  // slowloris: a line that never ends
        continue;
      }
      const bool logged_in = s->protocol == Protocol::kAnc300 ? s->anc.authorized : s->authorized;
      if (on_time && !logged_in && now - s->opened > login_timeout) {
        hostile(*s);
        continue;
      }
      if (s->waiting_axis >= 0) {
        if (auto reply = anc300.poll_wait(s->anc, s->waiting_axis)) {
          s->waiting_axis = -1;
          send(*s, std::move(*reply));
          process(*s);
          if (s->reading_done) {
            flush_then_close(*s);
          } else {
            read(s);
          }
        }
      }
    }
    timer.expires_after(heartbeat);
    timer.async_wait([this](boost::system::error_code ec) {
      if (!ec) housekeeping();
    });
  }
};

TwinServer::TwinServer(TwinStage& stage, TwinServerParams params) {
  params.validate();
  impl_ = std::make_unique<Impl>(stage, std::move(params));
}

TwinServer::~TwinServer() { stop(); }

void TwinServer::start() {
  if (impl_->running.exchange(true)) throw InvalidInput("twin server: already started");
  Impl& m = *impl_;
  for (const auto& e : m.params.endpoints) {
    boost::system::error_code ec;
    const auto address = asio::ip::make_address(e.address == "localhost" ? "127.0.0.1" : e.address, ec);
    const char* name = protocol_name(e.protocol);
    if (ec)
      throw InvalidInput(std::string("--emulate ") + name + ": '" + excerpt(e.address) +
                         "' is not an IP address");
    auto acc = std::make_unique<tcp::acceptor>(m.io);
    const tcp::endpoint ep(address, e.port);
    acc->open(ep.protocol(), ec);
    if (!ec) acc->set_option(tcp::acceptor::reuse_address(true), ec);
    if (!ec) acc->bind(ep, ec);
    if (!ec) acc->listen(asio::socket_base::max_listen_connections, ec);
    if (ec) {
      m.running = false;
      throw InvalidInput(std::string("--emulate ") + name + ": cannot listen on " + excerpt(e.address) + ":" +
                         std::to_string(e.port) + ": " + ec.message());
    }
    m.bound.push_back(acc->local_endpoint().port());
    m.acceptors.push_back(std::move(acc));
    m.acceptor_protocols.push_back(e.protocol);
    m.acceptor_tokened.push_back(!loopback_address(e.address));
  }
  for (std::size_t k = 0; k < m.acceptors.size(); ++k) m.accept(k);
  asio::post(m.io, [&m] { m.housekeeping(); });
  m.thread = std::thread([&m] { m.io.run(); });
}

void TwinServer::stop() {
  if (!impl_ || !impl_->running.load() || !impl_->thread.joinable()) return;
  Impl& m = *impl_;
  asio::post(m.io, [&m] {
    for (auto& a : m.acceptors) {
      boost::system::error_code ignored;
      a->close(ignored);
    }
    m.timer.cancel();
    std::vector<std::shared_ptr<Impl::Session>> all;
    for (auto& [id, s] : m.sessions) all.push_back(s);
    for (auto& s : all) m.close(*s);
    m.io.stop();
  });
  m.thread.join();
  m.running = false;
}

std::vector<std::uint16_t> TwinServer::ports() const { return impl_->bound; }

TwinServerCounters TwinServer::counters() const {
  std::lock_guard lock(impl_->counters_mutex);
  return impl_->counts;
}

}  // namespace mc::twins

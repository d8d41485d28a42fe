#include "microcobot/drivers/gcs2_exchange.h"

#include <fmt/format.h>

#include "microcobot/core/input_file.h"
#include "microcobot/drivers/bus_controller.h"
#include "microcobot/drivers/gcs2_codec.h"

namespace mc::drivers::gcs2 {

std::string line_name(const std::string& line) {
  return line.size() == 1 ? fmt::format("#{}", static_cast<int>(static_cast<unsigned char>(line[0])))
                          : excerpt(line, 60);
}

std::string query(LineClient& bus, const std::string& line, Clock::time_point deadline) {
  if (!bus.send(line.size() == 1 ? line : line + "\n", deadline))
    throw BusFault("'" + line_name(line) + "': " + bus.error());
  std::string reply;
  if (!bus.read_until(
          reply, [](const std::string& t) { return reply_end(t); }, deadline)) {
    const std::string got = reply.empty() ? std::string() : " (got '" + excerpt(reply, 60) + "')";
    throw BusFault("'" + line_name(line) + "': " + bus.error() + got);
  }
  return reply;
}

void command(LineClient& bus, const std::string& line, Clock::duration reply_timeout, ErrorText text,
             int also_ok) {
  if (!bus.send(line.size() == 1 ? line : line + "\n", Clock::now() + reply_timeout))
    throw BusFault("'" + line_name(line) + "': " + bus.error());
  const std::string reply = query(bus, "ERR?", Clock::now() + reply_timeout);
  const auto code = parse_error_reply(reply);
  if (!code)
    throw BusFault("'" + line_name(line) + "' then ERR?: a reply that is not an error code: '" +
                   excerpt(reply, 60) + "'");
  if (*code != 0 && *code != also_ok)
    throw BusFault(fmt::format("'{}': controller error {} ({})", line_name(line), *code, text(*code)));
}

void clear_errors(LineClient& bus, Clock::duration reply_timeout, int max_reads) {
  for (int n = 1;; ++n) {
    const auto code = parse_error_reply(query(bus, "ERR?", Clock::now() + reply_timeout));
    if (!code) throw BusFault("ERR?: not an error code");
    if (*code == 0) return;
    if (n >= max_reads) throw BusFault(fmt::format("ERR? still reads {} after {} reads", *code, n));
  }
}

}  // namespace mc::drivers::gcs2

// libFuzzer harness: what a controller sends the vendor drivers, what a client sends the
// MCS2 twin (its line and command parser) and the hexapod twin (the C-887 dialect's pose and pivot
// pairs, axis queries and coordinate system names), and the connection text of the configuration. A reply is
// either parsed (finite values, whole lines) or refused with one line (mc::Error); the reply framing never
// reads past its input; never a crash.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "microcobot/core/error.h"
#include "microcobot/drivers/anc300_codec.h"
#include "microcobot/drivers/gcs2_codec.h"
#include "microcobot/drivers/gcs2_hexapod.h"
#include "microcobot/drivers/line_client.h"
#include "microcobot/drivers/mcs2_codec.h"

namespace {

void one_line(const mc::Error& e) {
  if (std::string(e.what()).find('\n') != std::string::npos) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  namespace gcs2 = mc::drivers::gcs2;
  namespace anc300 = mc::drivers::anc300;
  if (gcs2::reply_end(text) > text.size()) std::abort();
  (void)gcs2::reply_lines(text);
  (void)gcs2::parse_error_reply(text);
  try {
    for (const auto& [axis, v] : gcs2::parse_axis_values(text))
      if (!std::isfinite(v) || axis.empty()) std::abort();
  } catch (const mc::Error& e) {
    one_line(e);
  }
  bool ok = false;
  if (anc300::reply_end(text, &ok) > text.size()) std::abort();
  for (const auto& line : anc300::reply_lines(text)) {
    if (line.find('\n') != std::string::npos) std::abort();
    if (const auto v = anc300::value_of(line); v && v->empty()) std::abort();
  }
  // MCS2: a client's line split and parsed (a command or an SCPI error, never both), a reply read.
  namespace mcs2 = mc::drivers::mcs2;
  for (const auto command : mcs2::split_commands(text)) {
    if (command.empty() || command.size() > text.size()) std::abort();
    mcs2::Command c;
    const int e = mcs2::parse_command(command, c);
    if (e == mcs2::kNoError && (c.header.empty() || c.index > 999)) std::abort();
    if (e != mcs2::kNoError && mcs2::error_text(e) == "Unknown error") std::abort();
    for (const auto& a : c.args) (void)mcs2::parse_rounded(a);
  }
  if (mcs2::reply_end(text) > text.size()) std::abort();
  if (const auto r = mcs2::parse_error_reply(text); r && r->second.find('"') != std::string::npos)
    std::abort();
  // The C-887 dialect: a line's arguments parsed as a pose, a pivot, a query and a system name; a
  // parse either fails with a GCS code and no value, or gives finite values only.
  if (const auto r = gcs2::parse_line(text)) {
    const auto pose = gcs2::parse_hexapod_values(r->args);
    for (const auto& v : pose.values)
      if ((pose.error != 0 && v) || (v && !std::isfinite(*v))) std::abort();
    if (pose.error == 0 && r->args.empty()) std::abort();
    const auto pivot = gcs2::parse_pivot_values(r->args);
    for (const auto& v : pivot.values)
      if ((pivot.error != 0 && v) || (v && !std::isfinite(*v))) std::abort();
    const auto q = gcs2::parse_hexapod_query(r->args);
    for (int i : q.axes)
      if (i < 0 || i >= 6 || q.error != 0) std::abort();
    if (const auto name = gcs2::parse_cs_name(r->mnemonic);
        name && (name->empty() || name->size() > gcs2::kMaxCsName))
      std::abort();
    if (gcs2::hexapod_error_text(pose.error).empty()) std::abort();
  }
  try {
    const auto c = mc::drivers::parse_connection(text, "pi-gcs2");
    if (c.is_serial() ? c.serial.path.front() != '/' || c.serial.baud == 0 : c.port == 0 || c.host.empty())
      std::abort();
  } catch (const mc::Error& e) {
    one_line(e);
  }
  return 0;
}

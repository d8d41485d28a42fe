#include "microcobot/drivers/mcs2_codec.h"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

namespace mc::drivers::mcs2 {
namespace {

/// SCPI's long forms of the nodes the controller knows, with their short forms: either spelling is
/// accepted, in any case.
constexpr std::array<std::pair<std::string_view, std::string_view>, 22> kLongForms{{
    {"CHANNEL", "CHAN"},  {"POSITION", "POS"},     {"CURRENT", "CURR"},   {"TARGET", "TARG"},
    {"VELOCITY", "VEL"},  {"ACCELERATION", "ACC"}, {"STATUS", "STAT"},    {"STATE", "STAT"},
    {"SYSTEM", "SYST"},   {"ERROR", "ERR"},        {"COUNT", "COUN"},     {"DEVICE", "DEV"},
    {"SENSOR", "SENS"},   {"TEMPERATURE", "TEMP"}, {"FREQUENCY", "FREQ"}, {"AMPLITUDE", "AMPL"},
    {"REFERENCE", "REF"}, {"OPTIONS", "OPT"},      {"TUNING", "TUN"},     {"RESOLUTION", "RES"},
    {"MODULE", "MOD"},    {"CALIBRATE", "CAL"},
}};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '\n'))
    s.remove_suffix(1);
  return s;
}

bool printable(char c) { return c >= 0x20 && c < 0x7f; }

}  // namespace

std::string_view error_text(int code) {
  switch (code) {
    case kNoError:
      return "No error";
    case kInvalidCharacter:
      return "Invalid character";
    case kInvalidSeparator:
      return "Invalid separator";
    case kDataTypeError:
      return "Data type error";
    case kParameterNotAllowed:
      return "Parameter not allowed";
    case kMissingParameter:
      return "Missing parameter";
    case kUndefinedHeader:
      return "Undefined header";
    case kHeaderSuffixOutOfRange:
      return "Header suffix out of range";
    case kDataOutOfRange:
      return "Data out of range";
    case kQueueOverflow:
      return "Queue overflow";
    case kInputBufferOverrun:
      return "Input buffer overrun";
    case kAborted:
      return "Aborted";
    case kInvalidModuleIndex:
      return "Invalid module index";
    case kInvalidChannelIndex:
      return "Invalid channel index";
    case kPermissionDenied:
      return "Permission denied";
    case kMovementLocked:
      return "Movement locked";
    case kNoSensorPresent:
      return "No sensor present";
    case kSensorDisabled:
      return "Sensor disabled";
    case kAmplifierDisabled:
      return "Amplifier disabled";
    case kNotReferenced:
      return "Not referenced";
    case kBusyReferencing:
      return "Busy referencing";
    case kRangeLimitReached:
      return "Range limit reached";
    case kFeatureNotImplemented:
      return "Feature not implemented";
    default:
      return "Unknown error";
  }
}

std::string format_error(int code) { return fmt::format("{},\"{}\"", code, error_text(code)); }

std::vector<std::string_view> split_commands(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  bool quoted = false;
  for (std::size_t i = 0; i <= line.size(); ++i) {
    if (i < line.size() && line[i] == '"') quoted = !quoted;
    if (i == line.size() || (line[i] == ';' && !quoted)) {
      const std::string_view c = trim(line.substr(start, i - start));
      if (!c.empty()) out.push_back(c);
      start = i + 1;
    }
  }
  return out;
}

int parse_command(std::string_view text, Command& out) {
  out = Command{};
  text = trim(text);
  for (char c : text)
    if (!printable(c) && c != '\t') return kInvalidCharacter;
  const std::size_t space = text.find_first_of(" \t");
  std::string_view header = text.substr(0, space);
  const std::string_view params =
      space == std::string_view::npos ? std::string_view{} : trim(text.substr(space));
  if (!header.empty() && header.back() == '?') {
    out.query = true;
    header.remove_suffix(1);
  }
  if (!header.empty() && header.front() == ':') header.remove_prefix(1);
  if (header.empty()) return kUndefinedHeader;
  // Each node: letters (a leading '*' for the common commands), then an optional numeric suffix.
  std::size_t start = 0;
  while (start <= header.size()) {
    std::size_t end = header.find(':', start);
    if (end == std::string_view::npos) end = header.size();
    const std::string_view node = header.substr(start, end - start);
    std::size_t letters = 0;
    if (!node.empty() && node[0] == '*' && start == 0) ++letters;
    while (letters < node.size() && std::isalpha(static_cast<unsigned char>(node[letters]))) ++letters;
    if (letters == 0 || (letters == 1 && node[0] == '*')) return kUndefinedHeader;
    const std::string_view digits = node.substr(letters);
    for (char c : digits)
      if (!std::isdigit(static_cast<unsigned char>(c))) return kUndefinedHeader;
    if (!digits.empty()) {
      if (out.index >= 0) return kUndefinedHeader;  // one suffix per command
      if (digits.size() > 3) return kHeaderSuffixOutOfRange;
      out.index = std::stoi(std::string(digits));
    }
    std::string name;
    for (char c : node.substr(0, letters))
      name += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    for (const auto& [long_form, short_form] : kLongForms)
      if (name == long_form) name = std::string(short_form);
    if (!out.header.empty()) out.header += ':';
    out.header += name;
    if (end == header.size()) break;
    start = end + 1;
  }
  if (params.empty()) return kNoError;
  if (params.front() == ',' || params.back() == ',') return kInvalidSeparator;
  std::size_t from = 0;
  for (;;) {
    const std::size_t comma = params.find(',', from);
    const std::string_view p =
        trim(params.substr(from, comma == std::string_view::npos ? params.npos : comma - from));
    if (p.empty()) return kInvalidSeparator;
    out.args.emplace_back(p);
    if (comma == std::string_view::npos) break;
    from = comma + 1;
  }
  return kNoError;
}

std::optional<std::int64_t> parse_integer(std::string_view word) {
  if (word.empty() || word.size() > 24) return std::nullopt;
  if (word.front() == '+') word.remove_prefix(1);
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
  if (ec != std::errc{} || end != word.data() + word.size()) return std::nullopt;
  return v;
}

std::optional<std::int64_t> parse_rounded(std::string_view word) {
  if (auto v = parse_integer(word)) return v;
  if (word.empty() || word.size() > 64) return std::nullopt;
  if (word.front() == '+') word.remove_prefix(1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
  if (ec != std::errc{} || end != word.data() + word.size() || !std::isfinite(v) || std::abs(v) > 9e18)
    return std::nullopt;
  return std::llround(v);
}

std::optional<std::pair<int, std::string>> parse_error_reply(std::string_view reply) {
  reply = trim(reply);
  const std::size_t comma = reply.find(',');
  if (comma == std::string_view::npos) return std::nullopt;
  const auto code = parse_integer(reply.substr(0, comma));
  std::string_view text = reply.substr(comma + 1);
  if (!code || *code < -100000 || *code > 100000 || text.size() < 2 || text.front() != '"' ||
      text.back() != '"')
    return std::nullopt;
  text = text.substr(1, text.size() - 2);
  if (text.find('"') != std::string_view::npos) return std::nullopt;
  return std::make_pair(static_cast<int>(*code), std::string(text));
}

std::size_t reply_end(std::string_view text) {
  const std::size_t lf = text.find('\n');
  return lf == std::string_view::npos ? 0 : lf + 1;
}

}  // namespace mc::drivers::mcs2

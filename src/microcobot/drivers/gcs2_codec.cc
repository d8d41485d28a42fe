#include "microcobot/drivers/gcs2_codec.h"

#include <cctype>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"

namespace mc::drivers::gcs2 {
namespace {

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

bool all_digits(std::string_view w) {
  if (w.empty() || w.size() > 3) return false;
  for (char c : w)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  return true;
}

}  // namespace

std::string_view error_text(int code) {
  switch (code) {
    case kNoError:
      return "No error";
    case kParameterSyntax:
      return "Parameter syntax error";
    case kUnknownCommand:
      return "Unknown command";
    case kCommandTooLong:
      return "Command length out of limits or command buffer overrun";
    case kUnallowableMove:
      return "Unallowable move attempted on unreferenced axis, or move attempted with servo off";
    case kPositionOutOfLimits:
      return "Position out of limits";
    case kVelocityOutOfLimits:
      return "Velocity out of limits";
    case kStopped:
      return "Controller was stopped by command";
    case kInvalidAxis:
      return "Invalid axis identifier";
    case kParameterOutOfRange:
      return "Parameter out of range";
    default:
      return "Unknown error";
  }
}

std::optional<Request> parse_line(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  auto w = words(line);
  if (w.empty()) return std::nullopt;
  Request r;
  std::size_t k = 0;
  if (all_digits(w[0]) && w.size() >= 2) {
    r.target_address = std::stoi(std::string(w[0]));
    k = 1;
  }
  for (char c : w[k]) r.mnemonic += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  for (std::size_t i = k + 1; i < w.size(); ++i) r.args.emplace_back(w[i]);
  return r;
}

std::string format_reply(const std::vector<std::string>& lines, int from_address) {
  std::string out;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (from_address > 0) out += fmt::format("0 {} ", from_address);
    out += lines[i];
    out += i + 1 < lines.size() ? " \n" : "\n";
  }
  return out;
}

std::string axis_value(std::string_view axis, double value) { return fmt::format("{}={:.6f}", axis, value); }
std::string axis_value(std::string_view axis, int value) { return fmt::format("{}={}", axis, value); }

std::optional<double> parse_number(std::string_view word) {
  if (word.empty() || word.size() > 64) return std::nullopt;
  if (word.front() == '+') word.remove_prefix(1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
  if (ec != std::errc{} || end != word.data() + word.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::vector<std::pair<std::string, double>> parse_axis_values(std::string_view reply) {
  std::vector<std::pair<std::string, double>> out;
  std::size_t start = 0;
  while (start < reply.size()) {
    std::size_t end = reply.find('\n', start);
    if (end == std::string_view::npos) end = reply.size();
    std::string_view line = reply.substr(start, end - start);
    start = end + 1;
    while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.remove_suffix(1);
    if (line.empty()) continue;
    // "0 1 1=0.5": the host and sender addresses of a daisy-chained reply.
    auto w = words(line);
    if (w.size() == 3 && all_digits(w[0]) && all_digits(w[1])) line = w[2];
    const auto eq = line.find('=');
    std::optional<double> v;
    if (eq != std::string_view::npos && eq > 0) v = parse_number(line.substr(eq + 1));
    if (!v) throw InvalidInput("GCS reply line '" + excerpt(line) + "': expected AXIS=NUMBER");
    out.emplace_back(std::string(line.substr(0, eq)), *v);
  }
  return out;
}

bool reply_complete(std::string_view text) {
  return !text.empty() && text.back() == '\n' && (text.size() < 2 || text[text.size() - 2] != ' ');
}

std::size_t reply_end(std::string_view text) {
  for (std::size_t i = 0; i < text.size(); ++i)
    if (text[i] == '\n' && (i == 0 || text[i - 1] != ' ')) return i + 1;
  return 0;
}

std::vector<std::string> reply_lines(std::string_view reply) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start < reply.size()) {
    std::size_t end = reply.find('\n', start);
    if (end == std::string_view::npos) end = reply.size();
    std::string_view line = reply.substr(start, end - start);
    start = end + 1;
    while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.remove_suffix(1);
    auto w = words(line);
    if (w.size() >= 3 && all_digits(w[0]) && all_digits(w[1])) line = line.substr(w[2].data() - line.data());
    out.emplace_back(line);
  }
  return out;
}

std::optional<int> parse_error_reply(std::string_view reply) {
  const auto lines = reply_lines(reply);
  if (lines.size() != 1) return std::nullopt;
  const auto v = parse_number(lines[0]);
  if (!v || *v != std::floor(*v) || std::abs(*v) > 1e6 || lines[0].find_first_of(".eE") != std::string::npos)
    return std::nullopt;
  return static_cast<int>(*v);
}

}  // namespace mc::drivers::gcs2

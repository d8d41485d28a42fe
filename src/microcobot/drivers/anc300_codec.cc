#include "microcobot/drivers/anc300_codec.h"

#include <cctype>
#include <charconv>
#include <cmath>

namespace mc::drivers::anc300 {
namespace {

constexpr std::pair<Mode, std::string_view> kModes[] = {
    {Mode::kGnd, "gnd"}, {Mode::kInp, "inp"},      {Mode::kCap, "cap"},       {Mode::kStp, "stp"},
    {Mode::kOff, "off"}, {Mode::kStpPlus, "stp+"}, {Mode::kStpMinus, "stp-"},
};

}  // namespace

std::string_view mode_name(Mode m) {
  for (const auto& [mode, name] : kModes)
    if (mode == m) return name;
  return "gnd";
}

std::optional<Mode> parse_mode(std::string_view name) {
  for (const auto& [mode, n] : kModes)
    if (n == name) return mode;
  return std::nullopt;
}

std::optional<Request> parse_line(std::string_view line) {
  while (!line.empty() && (line.back() == '\r' || line.back() == '\n')) line.remove_suffix(1);
  Request r;
  std::size_t i = 0;
  bool first = true;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i == start) continue;
    std::string w(line.substr(start, i - start));
    if (first) {
      for (char& c : w) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      r.command = std::move(w);
      first = false;
    } else {
      r.args.push_back(std::move(w));
    }
  }
  if (first) return std::nullopt;
  return r;
}

std::string value_line(std::string_view name, std::string_view value, std::string_view unit) {
  std::string s(name);
  s += " = ";
  s += value;
  if (!unit.empty()) {
    s += ' ';
    s += unit;
  }
  return s;
}

std::string reply_ok(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) (out += l) += kEol;
  (out += kOk) += kEol;
  return out;
}

std::string reply_error(std::string_view message) {
  std::string out(message);
  (out += kEol) += kError;
  return out += kEol;
}

std::optional<double> parse_number(std::string_view word) {
  if (word.empty() || word.size() > 64) return std::nullopt;
  if (word.front() == '+') word.remove_prefix(1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
  if (ec != std::errc{} || end != word.data() + word.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<long long> parse_count(std::string_view word) {
  if (word.empty() || word.size() > 18) return std::nullopt;
  long long v = 0;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
  if (ec != std::errc{} || end != word.data() + word.size() || v < 0) return std::nullopt;
  return v;
}

std::optional<std::string> value_of(std::string_view line) {
  const auto eq = line.find(" = ");
  if (eq == std::string_view::npos || eq == 0) return std::nullopt;
  std::string_view rest = line.substr(eq + 3);
  const auto sp = rest.find(' ');
  if (sp != std::string_view::npos) rest = rest.substr(0, sp);
  while (!rest.empty() && rest.back() == '\r') rest.remove_suffix(1);
  if (rest.empty()) return std::nullopt;
  return std::string(rest);
}

namespace {

std::string_view trimmed(std::string_view line) {
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.remove_suffix(1);
  while (line.size() >= 2 && line.substr(0, 2) == kPrompt) line.remove_prefix(2);
  while (!line.empty() && line.front() == ' ') line.remove_prefix(1);
  return line;
}

}  // namespace

std::size_t reply_end(std::string_view text, bool* ok) {
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) return 0;
    const std::string_view line = trimmed(text.substr(start, end - start));
    if (line == kOk || line == kError) {
      if (ok != nullptr) *ok = line == kOk;
      return end + 1;
    }
    start = end + 1;
  }
  return 0;
}

std::vector<std::string> reply_lines(std::string_view reply) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start < reply.size()) {
    std::size_t end = reply.find('\n', start);
    if (end == std::string_view::npos) end = reply.size();
    const std::string_view line = trimmed(reply.substr(start, end - start));
    start = end + 1;
    if (line == kOk || line == kError) break;
    if (!line.empty()) out.emplace_back(line);
  }
  return out;
}

}  // namespace mc::drivers::anc300

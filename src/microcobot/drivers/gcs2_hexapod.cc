#include "microcobot/drivers/gcs2_hexapod.h"

#include <cctype>

#include "microcobot/drivers/gcs2_codec.h"

namespace mc::drivers::gcs2 {

namespace {

std::string upper(std::string_view w) {
  std::string s(w);
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

template <std::size_t N>
int index_of(const std::array<const char*, N>& names, std::string_view word) {
  const std::string u = upper(word);
  for (std::size_t i = 0; i < N; ++i)
    if (u == names[i]) return static_cast<int>(i);
  return -1;
}

template <std::size_t N>
int parse_values(const std::array<const char*, N>& names, const std::vector<std::string>& args,
                 AxisValues<N>& out) {
  if (args.empty() || args.size() % 2 != 0) return kParameterSyntax;
  for (std::size_t k = 0; k < args.size(); k += 2) {
    const int i = index_of(names, args[k]);
    if (i < 0) return kInvalidAxis;
    auto& slot = out[static_cast<std::size_t>(i)];
    if (slot) return kAxisTwice;
    const auto v = parse_number(args[k + 1]);
    if (!v) return kParameterSyntax;
    slot = *v;
  }
  return kNoError;
}

template <std::size_t N>
QueriedAxes parse_query(const std::array<const char*, N>& names, const std::vector<std::string>& args) {
  QueriedAxes q;
  if (args.empty() || (args.size() == 1 && upper(args[0]) == "ALL")) {
    for (std::size_t i = 0; i < N; ++i) q.axes.push_back(static_cast<int>(i));
    return q;
  }
  for (const auto& a : args) {
    const int i = index_of(names, a);
    if (i < 0) {
      q.axes.clear();
      q.error = kInvalidAxis;
      return q;
    }
    q.axes.push_back(i);
  }
  return q;
}

}  // namespace

ParsedValues6 parse_hexapod_values(const std::vector<std::string>& args) {
  ParsedValues6 p;
  p.error = parse_values(kHexapodAxes, args, p.values);
  if (p.error) p.values = {};
  return p;
}

ParsedValues3 parse_pivot_values(const std::vector<std::string>& args) {
  ParsedValues3 p;
  p.error = parse_values(kPivotAxes, args, p.values);
  if (p.error) p.values = {};
  return p;
}

QueriedAxes parse_hexapod_query(const std::vector<std::string>& args) {
  return parse_query(kHexapodAxes, args);
}
QueriedAxes parse_pivot_query(const std::vector<std::string>& args) { return parse_query(kPivotAxes, args); }

std::optional<std::string> parse_cs_name(std::string_view word) {
  if (word.empty() || word.size() > kMaxCsName || !std::isalpha(static_cast<unsigned char>(word[0])))
    return std::nullopt;
  for (char c : word)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return std::nullopt;
  return upper(word);
}

std::string_view hexapod_error_text(int code) {
  switch (code) {
    case kSetPivotNotPossible:
      return "Attempt to set pivot point while U,V and W not all 0";
    case kAxisTwice:
      return "Axis identifier specified more than once";
    case kCsDoesNotExist:
      return "A command refers to a coordinate system that does not exist";
    case kCsInUse:
      return "Attempt to delete or change a coordinate system that is in use";
    case kCsWhileMoving:
      return "Coordinate system cannot be defined as long as Hexapod is in motion";
    case kCsNameInvalid:
      return "Name of coordinate system is invalid";
    case kControllerBusy:
      return "Controller is busy with some lengthy operation (e.g. reference move, fast scan algorithm)";
    default:
      return error_text(code);
  }
}

}  // namespace mc::drivers::gcs2

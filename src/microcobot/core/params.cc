#include "microcobot/core/params.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <unordered_set>

#include <fmt/format.h>

#include "microcobot/core/input_file.h"

namespace mc::detail {

namespace {

std::size_t line_of(const YAML::Node& node) {
  // yaml-cpp marks are 0-based; -1 when unknown.
  const auto mark = node.Mark();
  return mark.line >= 0 ? static_cast<std::size_t>(mark.line) + 1 : 0;
}

double to_double(const YAML::Node& node, bool& ok) {
  ok = false;
  if (!node.IsScalar()) return 0.0;
  const std::string& s = node.Scalar();
  try {
    std::size_t used = 0;
    const double v = std::stod(s, &used);
    if (used != s.size() || !std::isfinite(v)) return 0.0;
    ok = true;
    return v;
  } catch (const std::exception&) {
    return 0.0;
  }
}

}  // namespace

YamlReader::YamlReader(const YAML::Node& map, std::string source, std::string prefix)
    : map_(map), source_(std::move(source)), prefix_(std::move(prefix)) {
  if (!map_.IsMap()) {
    fail(map_, prefix_.empty() ? std::string("expected a map of parameters")
                               : fmt::format("'{}' must be a map", prefix_));
  }
}

std::string YamlReader::path(const char* key) const {
  return prefix_.empty() ? std::string(key) : prefix_ + "." + key;
}

void YamlReader::fail(const YAML::Node& node, const std::string& what) const {
  throw InvalidInput(source_, line_of(node), what);
}

YAML::Node YamlReader::lookup(const char* key) {
  used_.emplace_back(key);
  for (auto it = map_.begin(); it != map_.end(); ++it) {
    if (it->first.IsScalar() && it->first.Scalar() == key) return it->second;
  }
  return YAML::Node(YAML::NodeType::Undefined);
}

void YamlReader::read(const char* key, double& value) {
  const YAML::Node n = lookup(key);
  if (!n) return;
  bool ok = false;
  const double v = to_double(n, ok);
  if (!ok) fail(n, fmt::format("'{}' must be a finite number", path(key)));
  value = v;
}

void YamlReader::read(const char* key, int& value) {
  const YAML::Node n = lookup(key);
  if (!n) return;
  bool ok = false;
  const double v = to_double(n, ok);
  if (!ok || v != std::floor(v) || std::abs(v) > 2e9) {
    fail(n, fmt::format("'{}' must be an integer", path(key)));
  }
  value = static_cast<int>(v);
}

void YamlReader::read(const char* key, bool& value) {
  const YAML::Node n = lookup(key);
  if (!n) return;
  if (!n.IsScalar() || (n.Scalar() != "true" && n.Scalar() != "false")) {
    fail(n, fmt::format("'{}' must be true or false", path(key)));
  }
  value = n.Scalar() == "true";
}

void YamlReader::read(const char* key, std::string& value) {
  const YAML::Node n = lookup(key);
  if (!n) return;
  if (!n.IsScalar()) fail(n, fmt::format("'{}' must be a string", path(key)));
  value = n.Scalar();
}

void YamlReader::read(const char* key, std::vector<double>& value) {
  const YAML::Node n = lookup(key);
  if (!n) return;
  if (!n.IsSequence()) fail(n, fmt::format("'{}' must be a list of numbers", path(key)));
  std::vector<double> out;
  out.reserve(n.size());
  for (std::size_t i = 0; i < n.size(); ++i) {
    bool ok = false;
    out.push_back(to_double(n[i], ok));
    if (!ok) fail(n[i], fmt::format("'{}[{}]' must be a finite number", path(key), i));
  }
  value = std::move(out);
}

void YamlReader::read(const char* key, std::vector<std::vector<double>>& value) {
  const YAML::Node n = lookup(key);
  if (!n) return;
  if (!n.IsSequence()) fail(n, fmt::format("'{}' must be a list of lists", path(key)));
  std::vector<std::vector<double>> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node row = n[i];
    if (!row.IsSequence()) fail(row, fmt::format("'{}[{}]' must be a list", path(key), i));
    std::vector<double> r;
    for (std::size_t j = 0; j < row.size(); ++j) {
      bool ok = false;
      r.push_back(to_double(row[j], ok));
      if (!ok) fail(row[j], fmt::format("'{}[{}][{}]' must be a finite number", path(key), i, j));
    }
    out.push_back(std::move(r));
  }
  value = std::move(out);
}

void YamlReader::reject_unknown_keys() const {
  for (auto it = map_.begin(); it != map_.end(); ++it) {
    const std::string key = it->first.IsScalar() ? it->first.Scalar() : std::string("?");
    if (std::find(used_.begin(), used_.end(), key) == used_.end()) {
      std::string known;
      for (const auto& k : used_) known += (known.empty() ? "" : ", ") + k;
      throw InvalidInput(
          source_, line_of(it->first),
          fmt::format("unknown key '{}' (known: {})", excerpt(path(key.c_str())), excerpt(known, 200)));
    }
  }
}

namespace {

// Refuses a key repeated in one map (yaml-cpp keeps both and lookups would take the first,
// silently dropping the second, e.g. a repeated `friction:` section). `budget` bounds the
// walk: aliases share nodes, so a small file can describe an exponentially large tree.
void reject_duplicate_keys(const YAML::Node& node, const std::string& source, std::size_t& budget) {
  if (budget == 0)
    throw InvalidInput(source, line_of(node), "YAML too large (more than 100000 nodes, counting aliases)");
  --budget;
  if (node.IsMap()) {
    std::unordered_set<std::string> keys;
    for (auto it = node.begin(); it != node.end(); ++it) {
      if (it->first.IsScalar() && !keys.insert(it->first.Scalar()).second) {
        throw InvalidInput(source, line_of(it->first),
                           fmt::format("duplicate key '{}'", excerpt(it->first.Scalar())));
      }
      reject_duplicate_keys(it->second, source, budget);
    }
  } else if (node.IsSequence()) {
    for (auto it = node.begin(); it != node.end(); ++it) reject_duplicate_keys(*it, source, budget);
  }
}

}  // namespace

namespace {

// The line of a second document's marker ("---" or "..." followed by content), or 0. yaml-cpp
// 0.7's LoadAll() loops forever on some inputs (a lone ',': found by the parameter fuzzer), so
// the documents are told apart on the text: markers stand at the start of a line.
std::size_t second_document_line(const std::string& text) {
  bool content = false, ended = false;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t eol = std::min(text.find('\n', pos), text.size());
    const std::string_view line(text.data() + pos, eol - pos);
    ++line_no;
    const auto is_marker = [&](std::string_view m) {
      return line.substr(0, 3) == m &&
             (line.size() == 3 || line[3] == ' ' || line[3] == '\t' || line[3] == '\r');
    };
    std::size_t first = line.find_first_not_of(" \t\r");
    const bool blank = first == std::string_view::npos || line[first] == '#';
    if (is_marker("---")) {
      if (content || ended) return line_no;
      content = line.find_first_not_of(" \t\r", 3) != std::string_view::npos;  // "--- value"
    } else if (is_marker("...")) {
      ended = content;
    } else if (!blank && line[0] != '%') {
      if (ended) return line_no;
      content = true;
    }
    pos = eol + 1;
  }
  return 0;
}

}  // namespace

YAML::Node parse_yaml_text(const std::string& text, const std::string& source) {
  if (const std::size_t line = second_document_line(text)) {
    throw InvalidInput(source, line, "a second YAML document (a parameter file holds one)");
  }
  YAML::Node doc;
  try {
    doc = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    const std::size_t line = e.mark.line >= 0 ? static_cast<std::size_t>(e.mark.line) + 1 : 0;
    throw InvalidInput(source, line, "malformed YAML: " + excerpt(e.msg));
  }
  std::size_t budget = 100000;
  reject_duplicate_keys(doc, source, budget);
  return doc;
}

YAML::Node parse_yaml_file(const std::filesystem::path& file) {
  return parse_yaml_text(read_input_file(file, kMaxParamsFileBytes, "parameter file"), file.string());
}

}  // namespace mc::detail

namespace mc {

namespace {
void emit(YAML::Emitter& out, const nlohmann::json& v) {
  if (v.is_object()) {
    out << YAML::BeginMap;
    for (auto it = v.begin(); it != v.end(); ++it) {
      out << YAML::Key << it.key() << YAML::Value;
      emit(out, it.value());
    }
    out << YAML::EndMap;
  } else if (v.is_array()) {
    const bool flat = std::none_of(v.begin(), v.end(), [](const auto& e) { return e.is_structured(); });
    out << (flat ? YAML::Flow : YAML::Block) << YAML::BeginSeq;
    for (const auto& e : v) emit(out, e);
    out << YAML::EndSeq;
  } else if (v.is_boolean()) {
    out << (v.get<bool>() ? "true" : "false");
  } else if (v.is_number_integer()) {
    out << v.get<long long>();
  } else if (v.is_number()) {
    out << fmt::format("{}", v.get<double>());  // shortest round-trip representation
  } else if (v.is_string()) {
    out << YAML::DoubleQuoted << v.get<std::string>();
  } else {
    out << YAML::Null;
  }
}
}  // namespace

std::string json_to_yaml(const nlohmann::json& value) {
  YAML::Emitter out;
  emit(out, value);
  return std::string(out.c_str()) + "\n";
}

}  // namespace mc

#pragma once
/// @file
/// Parameter structs: declared once, read from YAML, printed as JSON/YAML, validated.
///
/// A Params struct lists its fields in a `visit` member, with SI units in the key names:
/// @code
///   struct PiezoParams {
///     double mass_kg = 5.3e-3;
///     std::vector<double> thresholds_V;
///     ModeParams mode1;                       // nested Params: a YAML map
///     template <class V> void visit(V& v) {
///       v("mass_kg", mass_kg);
///       v("thresholds_V", thresholds_V);
///       v("mode1", mode1);
///     }
///     void validate() const;                  // throws mc::InvalidParams naming the field
///   };
/// @endcode
/// Supported field types: double, int, bool, std::string, std::vector<double>,
/// std::vector<std::vector<double>>, nested structs with `visit`, and lists of them
/// (std::vector<S>: a YAML list of maps that replaces the whole list, each element read over
/// S's defaults, e.g. a turret's objectives).
/// load_params() starts from the defaults and overrides the keys present in the file; an
/// unknown key, a wrong type or a malformed file throws mc::InvalidInput "file:line: ...".
/// params_to_json() prints exactly the keys load_params() accepts.

#include <filesystem>
#include <string>
#include <type_traits>
#include <vector>

#include <yaml-cpp/yaml.h>
#include <nlohmann/json.hpp>

#include "microcobot/core/error.h"

namespace mc {

namespace detail {

template <class T, class = void>
struct HasVisit : std::false_type {};
struct NullVisitor {
  template <class U>
  void operator()(const char*, U&) {}
};
template <class T>
struct HasVisit<T, std::void_t<decltype(std::declval<T&>().visit(std::declval<NullVisitor&>()))>>
    : std::true_type {};

template <class T>
struct IsParamsList : std::false_type {};
template <class S>
struct IsParamsList<std::vector<S>> : HasVisit<S> {};

template <class T, class = void>
struct HasValidate : std::false_type {};
template <class T>
struct HasValidate<T, std::void_t<decltype(std::declval<const T&>().validate())>> : std::true_type {};

/// Reads fields from one YAML map, remembering which keys were used.
class YamlReader {
 public:
  YamlReader(const YAML::Node& map, std::string source, std::string prefix);

  void read(const char* key, double& value);
  void read(const char* key, int& value);
  void read(const char* key, bool& value);
  void read(const char* key, std::string& value);
  void read(const char* key, std::vector<double>& value);
  void read(const char* key, std::vector<std::vector<double>>& value);

  template <class T>
  void operator()(const char* key, T& value) {
    if constexpr (HasVisit<T>::value) {
      const YAML::Node child = lookup(key);
      if (!child) return;
      YamlReader sub(child, source_, path(key));
      value.visit(sub);
      sub.reject_unknown_keys();
    } else if constexpr (IsParamsList<T>::value) {
      const YAML::Node list = lookup(key);
      if (!list) return;
      if (!list.IsSequence()) fail(list, "'" + path(key) + "' must be a list of maps");
      T out;
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string at = path(key) + "[" + std::to_string(i) + "]";
        if (!list[i].IsMap()) fail(list[i], "'" + at + "' must be a map");
        typename T::value_type element{};
        YamlReader sub(list[i], source_, at);
        element.visit(sub);
        sub.reject_unknown_keys();
        out.push_back(std::move(element));
      }
      value = std::move(out);
    } else {
      read(key, value);
    }
  }

  /// Throws InvalidInput naming the first key of the map that no field consumed.
  void reject_unknown_keys() const;

 private:
  YAML::Node lookup(const char* key);
  std::string path(const char* key) const;
  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const;

  YAML::Node map_;
  std::string source_;
  std::string prefix_;
  std::vector<std::string> used_;
};

/// Writes fields into a JSON object.
class JsonWriter {
 public:
  explicit JsonWriter(nlohmann::json& out) : out_(out) {}
  template <class T>
  void operator()(const char* key, T& value) {
    if constexpr (HasVisit<T>::value) {
      nlohmann::json child = nlohmann::json::object();
      JsonWriter sub(child);
      value.visit(sub);
      out_[key] = std::move(child);
    } else if constexpr (IsParamsList<T>::value) {
      nlohmann::json list = nlohmann::json::array();
      for (auto& element : value) {
        nlohmann::json child = nlohmann::json::object();
        JsonWriter sub(child);
        element.visit(sub);
        list.push_back(std::move(child));
      }
      out_[key] = std::move(list);
    } else {
      out_[key] = value;
    }
  }

 private:
  nlohmann::json& out_;
};

/// Parses a YAML document (file or text) into a node, errors as InvalidInput with the line.
YAML::Node parse_yaml_file(const std::filesystem::path& file);
YAML::Node parse_yaml_text(const std::string& text, const std::string& source);

}  // namespace detail

/// Reads `node` (a YAML map) over `defaults`, then validates. `source` names the origin in
/// error messages (usually the file name).
template <class P>
P params_from_yaml(const YAML::Node& node, const std::string& source, P defaults = P{}) {
  if (!node.IsNull()) {
    detail::YamlReader reader(node, source, "");
    defaults.visit(reader);
    reader.reject_unknown_keys();
  }
  if constexpr (detail::HasValidate<P>::value) defaults.validate();
  return defaults;
}

/// Reads a YAML (or JSON) parameter file over `defaults` and validates the result.
template <class P>
P load_params(const std::filesystem::path& file, P defaults = P{}) {
  return params_from_yaml(detail::parse_yaml_file(file), file.string(), std::move(defaults));
}

/// Parses parameters from YAML text (tests, inline configuration).
template <class P>
P params_from_yaml_text(const std::string& text, P defaults = P{}) {
  return params_from_yaml(detail::parse_yaml_text(text, "<yaml>"), "<yaml>", std::move(defaults));
}

/// Every field of `params`, in the keys load_params() accepts.
template <class P>
nlohmann::json params_to_json(P params) {
  nlohmann::json out = nlohmann::json::object();
  detail::JsonWriter writer(out);
  params.visit(writer);
  return out;
}

/// The same as params_to_json() as block YAML (for parameter files written by identification).
std::string json_to_yaml(const nlohmann::json& value);

template <class P>
std::string params_to_yaml(const P& params) {
  return json_to_yaml(params_to_json(params));
}

}  // namespace mc

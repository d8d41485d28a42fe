#pragma once
// Conversions shared by the binding translation units (python/*.cc): parameters between Python
// dicts / YAML files and the library's Params structs (through their visit(), the same keys as
// `microcobot <group> params --json`), numpy arrays in and out, and the checks on array inputs.
// No model logic lives here.

#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <yaml-cpp/yaml.h>

#include "microcobot/core/error.h"
#include "microcobot/core/params.h"

namespace mc::platform {
struct PlatformConfig;
}

namespace mc::py {

namespace py = pybind11;

/// A C-contiguous float64 array (numpy converts lists and other dtypes on the way in).
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// A Python value (dict, list, number, bool, str) as a YAML node, so that the library's own
/// params_from_yaml() checks keys and types with its usual one-line messages.
YAML::Node to_yaml(py::handle value, const std::string& where);

/// Parameters from None (the defaults), a dict (keys as `params --json` prints them; missing keys
/// keep their default), or a path to a YAML/JSON file. Validated; bad values raise ValueError with
/// the CLI's message.
template <class P>
P params_from(py::handle obj) {
  if (obj.is_none()) {
    P p;
    if constexpr (detail::HasValidate<P>::value) p.validate();
    return p;
  }
  if (py::isinstance<py::str>(obj) || py::hasattr(obj, "__fspath__")) {
    const auto path = py::str(py::module_::import("os").attr("fspath")(obj)).cast<std::string>();
    return load_params<P>(std::filesystem::path(path));
  }
  if (!py::isinstance<py::dict>(obj)) {
    throw InvalidInput("parameters must be a dict, a YAML file name or None (got " +
                       py::str(py::type::of(obj).attr("__name__")).cast<std::string>() + ")");
  }
  return params_from_yaml<P>(to_yaml(obj, "<dict>"), "<dict>");
}

/// JSON value -> Python object (dict, list, float, int, bool, str, None).
py::object from_json(const nlohmann::json& j);

/// Every field of `p` as a nested dict (params_to_json()).
template <class P>
py::dict params_dict(const P& p) {
  return from_json(params_to_json(p));
}

/// A 1-D float64 numpy array copied from `v`.
inline py::array_t<double> to_array(std::span<const double> v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

/// Raises ValueError "<name>: ..." unless `a` has `ndim` dimensions, and `min_size` samples or more
/// along its last one; then unless every value is finite (naming the first bad index).
void check_array(const DoubleArray& a, const std::string& name, int ndim, py::ssize_t min_size = 1);

/// `a` (checked: 1-D, finite) as a span over its data (valid while `a` lives).
inline std::span<const double> span_of(const DoubleArray& a, const std::string& name,
                                       py::ssize_t min_size = 1) {
  check_array(a, name, 1, min_size);
  return {a.data(), static_cast<std::size_t>(a.size())};
}

/// An array input of items of one shape: one item (shape `item`) or N of them (shape (N, *item)),
/// as C-contiguous float64 (not copied when it already is). A batch of rows for the vectorised
/// calls (e.g. poses (N, 6)); a single item gives a result without the N axis.
struct ArrayRows {
  DoubleArray a;
  std::string name;
  py::ssize_t n = 0;
  bool single = false;
  std::vector<py::ssize_t> item;
  /// "poses[3]" (or "poses" for a single item): names a row in messages.
  std::string row(py::ssize_t i) const;
  /// The shape of a result of `out_item` items per input item.
  std::vector<py::ssize_t> shape(const std::vector<py::ssize_t>& out_item) const;
};

/// `obj` as ArrayRows; raises ValueError "<name>: expected shape (N, 6) or (6,) (got (3, 5))".
ArrayRows array_rows(py::handle obj, const std::string& name, std::vector<py::ssize_t> item);

/// Raises ValueError "<name>[i]: non-finite value nan" at the first non-finite value.
void require_finite(const ArrayRows& r);

/// The result array of a vectorised call: a new one, or the caller's `out` (as MuJoCo's `out=`: a
/// loop of calls reuses it instead of allocating), checked to be a writeable C-contiguous float64
/// array of `shape` that shares no memory with `inputs` unless it is one of them exactly (the
/// calls read each row before they write it). Raises ValueError "out: expected ..." otherwise.
py::array_t<double> output_array(py::handle out, const std::vector<py::ssize_t>& shape,
                                 std::initializer_list<const ArrayRows*> inputs);

/// A per-row result (an array or a list) as it is, or its one value as a Python scalar.
py::object per_row(py::object o, bool single);

/// Raises ComputationFailed unless every value of `v` is finite (no call returns NaN).
void require_finite_result(std::span<const double> v, const std::string& what);

/// A platform configuration from None (the defaults), a dict (keys of `microcobot run
/// --print-config`) or a file: a file goes through load_platform_config (its stickslip_params_file
/// is relative to it), as `microcobot run --config`. Defined in control_py.cc.
platform::PlatformConfig config_from(py::handle c);

// The submodules, one function per translation unit.
void bind_stickslip(py::module_& m);
void bind_identify(py::module_& m);
void bind_dsp(py::module_& m);
void bind_control(py::module_& m);
void bind_platform(py::module_& m);
void bind_haptics(py::module_& m);
void bind_tweezers(py::module_& m);
void bind_vision(py::module_& m);
void bind_cell(py::module_& m);
void bind_positioner(py::module_& m);

}  // namespace mc::py

namespace mc::py {
/// Runs `f` with the GIL released (library computations; they touch no Python object).
template <class F>
auto nogil(F&& f) {
  pybind11::gil_scoped_release release;
  return f();
}
}  // namespace mc::py

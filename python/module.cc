// The extension module `microcobot._microcobot`: error translation and the shared conversions;
// the submodules are bound in stickslip_py.cc, dsp_py.cc, control_py.cc, vision_py.cc, cell_py.cc and
// positioner_py.cc.

#include <algorithm>
#include <sstream>

#include <fmt/format.h>

#include "common.h"
#include "microcobot/core/error.h"

namespace mc::py {

YAML::Node to_yaml(py::handle value, const std::string& where) {
  if (value.is_none()) return YAML::Node(YAML::NodeType::Null);
  if (py::isinstance<py::dict>(value)) {
    YAML::Node node(YAML::NodeType::Map);
    for (const auto& [k, v] : value.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k)) {
        throw InvalidInput(where + ": parameter keys must be strings (got " +
                           py::repr(k).cast<std::string>() + ")");
      }
      const auto key = k.cast<std::string>();
      node[key] = to_yaml(v, where + "." + key);
    }
    return node;
  }
  if (py::isinstance<py::bool_>(value)) return YAML::Node(value.cast<bool>());
  if (py::isinstance<py::int_>(value)) return YAML::Node(value.cast<long long>());
  if (py::isinstance<py::float_>(value)) return YAML::Node(value.cast<double>());
  if (py::isinstance<py::str>(value)) return YAML::Node(value.cast<std::string>());
  if (py::hasattr(value, "tolist")) return to_yaml(value.attr("tolist")(), where);  // numpy arrays, scalars
  if (py::isinstance<py::sequence>(value)) {
    YAML::Node node(YAML::NodeType::Sequence);
    for (const auto& item : value.cast<py::sequence>()) node.push_back(to_yaml(item, where));
    return node;
  }
  throw InvalidInput(where + ": unsupported value type " +
                     py::str(py::type::of(value).attr("__name__")).cast<std::string>());
}

py::object from_json(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [k, v] : j.items()) d[py::str(k)] = from_json(v);
      return d;
    }
    case nlohmann::json::value_t::array: {
      py::list l;
      for (const auto& v : j) l.append(from_json(v));
      return l;
    }
    case nlohmann::json::value_t::boolean:
      return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer:
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(j.get<long long>());
    case nlohmann::json::value_t::number_float:
      return py::float_(j.get<double>());
    case nlohmann::json::value_t::string:
      return py::str(j.get<std::string>());
    default:
      return py::none();
  }
}

void check_array(const DoubleArray& a, const std::string& name, int ndim, py::ssize_t min_size) {
  if (a.ndim() != ndim) {
    throw InvalidInput(name + ": expected a " + std::to_string(ndim) + "-D array (got " +
                       std::to_string(a.ndim()) + "-D)");
  }
  if (a.shape(ndim - 1) < min_size) {
    throw InvalidInput(name + ": expected at least " + std::to_string(min_size) + " samples (got " +
                       std::to_string(a.shape(ndim - 1)) + ")");
  }
  const double* d = a.data();
  for (py::ssize_t i = 0; i < a.size(); ++i) {
    if (!std::isfinite(d[i])) {
      std::ostringstream os;
      os << name << ": non-finite value " << d[i] << " at flat index " << i;
      throw InvalidInput(os.str());
    }
  }
}

namespace {

/// "(N, 6)" (batch) or "(6,)": a shape as numpy prints it.
std::string shape_text(const std::vector<py::ssize_t>& s, bool batch) {
  std::string t = batch ? "(N" : "(";
  for (std::size_t i = 0; i < s.size(); ++i) t += (i == 0 && !batch ? "" : ", ") + std::to_string(s[i]);
  return t + (s.size() == 1 && !batch ? ",)" : ")");
}

}  // namespace

std::string ArrayRows::row(py::ssize_t i) const {
  return single ? name : name + "[" + std::to_string(i) + "]";
}

std::vector<py::ssize_t> ArrayRows::shape(const std::vector<py::ssize_t>& out_item) const {
  std::vector<py::ssize_t> s;
  if (!single) s.push_back(n);
  s.insert(s.end(), out_item.begin(), out_item.end());
  return s;
}

ArrayRows array_rows(py::handle obj, const std::string& name, std::vector<py::ssize_t> item) {
  ArrayRows b{DoubleArray::ensure(obj), name, 0, false, std::move(item)};
  const auto nd = static_cast<py::ssize_t>(b.item.size());
  const std::string want = shape_text(b.item, true) + " or " + shape_text(b.item, false);
  if (!b.a) throw InvalidInput(name + ": expected an array of numbers of shape " + want);
  std::vector<py::ssize_t> got(b.a.shape(), b.a.shape() + b.a.ndim());
  const bool single = b.a.ndim() == nd && got == b.item;
  const bool batch = b.a.ndim() == nd + 1 && std::equal(b.item.begin(), b.item.end(), got.begin() + 1);
  if (!single && !batch)
    throw InvalidInput(name + ": expected shape " + want + " (got " + shape_text(got, false) + ")");
  b.single = single;
  b.n = single ? 1 : got[0];
  return b;
}

void require_finite(const ArrayRows& b) {
  const py::ssize_t w = b.a.size() / std::max<py::ssize_t>(b.n, 1);
  for (py::ssize_t i = 0; i < b.a.size(); ++i) {
    if (!std::isfinite(b.a.data()[i]))
      throw InvalidInput(b.row(i / w) + ": non-finite value " + fmt::format("{}", b.a.data()[i]));
  }
}

py::array_t<double> output_array(py::handle out, const std::vector<py::ssize_t>& shape,
                                 std::initializer_list<const ArrayRows*> inputs) {
  if (out.is_none()) return py::array_t<double>(shape);
  const std::string want = "a writeable C-contiguous float64 array of shape " + shape_text(shape, false);
  if (!py::isinstance<py::array>(out)) throw InvalidInput("out: expected " + want);
  const auto any = py::reinterpret_borrow<py::array>(out);
  std::vector<py::ssize_t> got(any.shape(), any.shape() + any.ndim());
  if (!py::isinstance<py::array_t<double>>(out))  // float64 in the machine's byte order
    throw InvalidInput("out: expected " + want + " (got dtype " + py::str(any.dtype()).cast<std::string>() +
                       ")");
  if (got != shape)
    throw InvalidInput("out: expected " + want + " (got shape " + shape_text(got, false) + ")");
  if (!(any.flags() & py::array::c_style))
    throw InvalidInput("out: expected " + want + " (got a non-C-contiguous array)");
  if (!any.writeable()) throw InvalidInput("out: expected " + want + " (got a read-only array)");
  auto a = py::reinterpret_borrow<py::array_t<double>>(out);
  const double* lo = a.data();
  const double* hi = lo + a.size();
  for (const ArrayRows* in : inputs) {
    if (in == nullptr || !in->a || in->a.size() == 0) continue;
    const double* ilo = in->a.data();
    const double* ihi = ilo + in->a.size();
    if (lo < ihi && ilo < hi && !(ilo == lo && ihi == hi))
      throw InvalidInput("out: shares memory with " + in->name + " (only the very same array may be both)");
  }
  return a;
}

py::object per_row(py::object o, bool single) {
  if (!single) return o;
  return py::isinstance<py::list>(o) ? py::object(o[py::int_(0)]) : o.attr("item")(0);
}

void require_finite_result(std::span<const double> v, const std::string& what) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      throw ComputationFailed(what + ": non-finite result at index " + std::to_string(i));
    }
  }
}

}  // namespace mc::py

PYBIND11_MODULE(_microcobot, m) {
  namespace py = pybind11;
  m.doc() =
      "microcobot: the micro-manipulation platform's library (thesis models, identification, DSP, "
      "control). SI units everywhere (m, s, V, N, Hz).";
  // Computation failures (divergence, no convergence): the CLI's exit code 4. Invalid parameters
  // and inputs (exit codes 2 and 3) become ValueError with the CLI's one-line message.
  static py::exception<mc::ComputationFailed> computation_failed(m, "ComputationFailed", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const mc::ComputationFailed& e) {
      computation_failed(e.what());
    } catch (const mc::Error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  m.attr("__version__") = MC_PY_VERSION;

  auto ss =
      m.def_submodule("stickslip", "Stick-slip actuator of thesis ch. 2: parameters, simulation, rollout");
  mc::py::bind_stickslip(ss);
  auto id = m.def_submodule("identify",
                            "Identification of the stick-slip axis from measured records (thesis §2.5)");
  mc::py::bind_identify(id);
  auto dsp = m.def_submodule("dsp", "Filters and spectra with scipy.signal's signatures where they overlap");
  mc::py::bind_dsp(dsp);
  auto ctl = m.def_submodule("control", "Velocity and position control of a stick-slip axis (thesis §2.7)");
  mc::py::bind_control(ctl);
  auto pf = m.def_submodule("platform", "The platform: scenario runs and recordings (CSV, MCAP, .mat)");
  mc::py::bind_platform(pf);
  auto hp = m.def_submodule("haptics", "The dual-stage haptic interface's rendering pipeline (thesis ch. 3)");
  mc::py::bind_haptics(hp);
  auto tw = m.def_submodule("tweezers", "TéléTweez design calculators (thesis ch. 4, app. A-B)");
  mc::py::bind_tweezers(tw);
  auto vs = m.def_submodule("vision", "The microscope camera: rendered frames and optics figures");
  mc::py::bind_vision(vs);
  auto cl = m.def_submodule(
      "cell", "The assembly cell: batches of pin insertions by mode, their results and summaries");
  mc::py::bind_cell(cl);
  auto pos = m.def_submodule(
      "positioner",
      "The 6-DOF parallel positioner (thesis §2.3, Fig. 2.4): inverse and forward kinematics, "
      "reachability, Jacobian and workspace over (N, 6) arrays");
  mc::py::bind_positioner(pos);
}

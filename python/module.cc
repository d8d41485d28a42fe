// The extension module `microcobot._microcobot`: error translation and the shared conversions;
// the submodules are bound in stickslip_py.cc, dsp_py.cc, control_py.cc, vision_py.cc, cell_py.cc and
// positioner_py.cc.

#include <sstream>

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

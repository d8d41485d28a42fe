// `microcobot.cell`: the assembly cell's batches made from a scene and run
// by mode, each cycle's result as a dict (CycleResult::to_json) and the summary of a list of them
// (summarize). The campaign over many seeds with Dask is pure Python over these calls
// (microcobot/cell.py).
//
// A translation unit of its own: the cell pulls in the platform's headers, and a change to the cell
// then recompiles this file alone rather than the control/platform bindings beside it (pybind11
// compiles slowly; one more TU costs one more parse of its headers, ~15 s, once).

#include <atomic>
#include <cctype>
#include <climits>
#include <optional>

#include "common.h"
#include "microcobot/cell/assembly_batch.h"
#include "microcobot/cell/cell_run.h"
#include "microcobot/cell/task_file.h"
#include "microcobot/platform/platform_config.h"

namespace mc::py {
namespace {

namespace cl = mc::cell;
using namespace pybind11::literals;

std::string type_name(py::handle v) { return py::str(py::type::of(v).attr("__name__")).cast<std::string>(); }

/// What the user gave, for messages: its type and repr (cut to keep the message one line).
std::string given(py::handle v) {
  std::string r = py::repr(v).cast<std::string>();
  if (r.size() > 60) r = r.substr(0, 57) + "...";
  return type_name(v) + " " + r;
}

/// None, or a Python int (a bool is refused) that fits an int. pybind11's own conversion error
/// lists every signature on several lines: the arguments are checked here, one line each.
std::optional<int> optional_int(py::handle v, const std::string& name) {
  if (v.is_none()) return std::nullopt;
  if (py::isinstance<py::bool_>(v) || !py::isinstance<py::int_>(v))
    throw py::type_error(name + ": expected an int (got " + given(v) + ")");
  int overflow = 0;
  const long long x = PyLong_AsLongLongAndOverflow(v.ptr(), &overflow);
  if (overflow != 0 || x < INT_MIN || x > INT_MAX)
    throw InvalidInput(name + ": " + py::repr(v).cast<std::string>() + " is out of range");
  return static_cast<int>(x);
}

/// Parameters of type P from `arg` (params_from), a dict's errors named after the argument: "scene:
/// unknown key 'x'" rather than the generic "<dict>: ...".
template <class P>
P named_params(py::handle arg, const std::string& name) {
  try {
    return params_from<P>(arg);
  } catch (const InvalidInput& e) {
    std::string what = e.what();
    if (what.rfind("<dict>", 0) == 0) throw InvalidInput(name + what.substr(6));
    throw;
  }
}

/// The run's parameters: `params` (None, dict or YAML file, as --params) with `mode` over them (a
/// str passed through as it is: the library knows the modes, so a new one needs no change here).
cl::CellRunParams run_params_from(py::handle params, py::handle mode) {
  cl::CellRunParams p = named_params<cl::CellRunParams>(params, "params");
  if (!mode.is_none()) {
    if (!py::isinstance<py::str>(mode))
      throw py::type_error("mode: expected a str (got " + given(mode) + ")");
    p.mode = mode.cast<std::string>();
  }
  p.validate();
  return p;
}

/// A Python value (dict, list, str, bool, int, float, None) as JSON.
nlohmann::json to_json_value(py::handle v, const std::string& where) {
  if (v.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>();
  if (py::isinstance<py::int_>(v)) return v.cast<long long>();
  if (py::isinstance<py::float_>(v)) return v.cast<double>();
  if (py::isinstance<py::str>(v)) return v.cast<std::string>();
  if (py::isinstance<py::dict>(v)) {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& [k, x] : v.cast<py::dict>()) {
      const std::string key = py::str(k).cast<std::string>();
      j[key] = to_json_value(x, where + "." + key);
    }
    return j;
  }
  if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& x : v) j.push_back(to_json_value(x, where));
    return j;
  }
  if (py::hasattr(v, "item")) return to_json_value(v.attr("item")(), where);  // numpy scalars
  throw InvalidInput(where + ": unsupported value " + given(v));
}

/// One batch: the scene's parameters and the parts they give (assembly_jobs), made once.
struct Batch {
  cl::AssemblyBatchParams scene;
  std::vector<cl::AssemblyJob> jobs;

  Batch(py::handle scene_arg, py::handle parts, py::handle seed) {
    scene = named_params<cl::AssemblyBatchParams>(scene_arg, "scene");
    if (const auto n = optional_int(parts, "parts")) scene.parts = *n;
    if (const auto s = optional_int(seed, "seed")) scene.seed = *s;
    jobs = cl::assembly_jobs(scene);  // validates
  }

  const cl::AssemblyJob& job(py::handle index) const {
    const auto i = optional_int(index, "index");
    if (!i) throw py::type_error("index: expected an int (got None)");
    if (*i < 0 || *i >= static_cast<int>(jobs.size()))
      throw InvalidInput("index: " + std::to_string(*i) + " is not a part of this batch of " +
                         std::to_string(jobs.size()) + " (0-" + std::to_string(jobs.size() - 1) + ")");
    return jobs[static_cast<std::size_t>(*i)];
  }
};

/// A task (None, a dict or a YAML file, as `cell run --task`) over the run parameters: the steps'
/// autonomy and the task's parameters over `p.task`.
void apply_task(py::handle task, cl::CellRunParams& p) {
  if (task.is_none()) return;
  cl::AssemblyTaskFile f;
  try {
    if (py::isinstance<py::str>(task) || py::hasattr(task, "__fspath__")) {
      const auto path = py::str(py::module_::import("os").attr("fspath")(task)).cast<std::string>();
      f = cl::load_task_file(path, p.task);
    } else if (py::isinstance<py::dict>(task)) {
      YAML::Emitter out;
      out << to_yaml(task, "task");
      f = cl::task_file_from_yaml(out.c_str(), p.task);
    } else {
      throw py::type_error("task: expected a dict, a YAML file name or None (got " + given(task) + ")");
    }
  } catch (const InvalidInput& e) {
    // "<yaml>:2: unknown key ..." names the text the dict was written to: name the argument, without
    // a line number the caller never wrote.
    std::string what = e.what();
    if (what.rfind("<yaml>", 0) == 0) {
      std::size_t rest = 6;
      if (rest < what.size() && what[rest] == ':') {
        std::size_t k = rest + 1;
        while (k < what.size() && std::isdigit(static_cast<unsigned char>(what[k]))) ++k;
        if (k > rest + 1 && k < what.size() && what[k] == ':') rest = k;
      }
      throw InvalidInput("task" + what.substr(rest));
    }
    throw;
  }
  p.task = f.params;
  p.autonomy = f.steps.autonomy();
}

/// One part's cycle, stepped from Python: the operator's controls reach the automatic task between
/// run_for() calls.
struct Cycle {
  std::unique_ptr<cl::CellCycle> cycle;
  std::string mode;
  /// Set while run_for() simulates without the GIL: another Python thread's call meanwhile would
  /// race the loop on the task, so it is refused.
  std::shared_ptr<std::atomic<bool>> running = std::make_shared<std::atomic<bool>>(false);

  /// Throws while another thread runs this cycle.
  cl::CellCycle& idle(const char* call) {
    if (running->load())
      throw py::value_error(std::string(call) +
                            ": the cycle is running in another thread (wait for its run_for)");
    return *cycle;
  }
  /// Runs `f` without the GIL, the cycle marked as running.
  template <class F>
  void run(const char* call, F&& f) {
    idle(call);
    running->store(true);
    try {
      nogil(std::forward<F>(f));
    } catch (...) {
      running->store(false);
      throw;
    }
    running->store(false);
  }

  cl::AssemblyTask& task(const char* control) {
    idle(control);
    if (cycle->task() == nullptr)
      throw InvalidInput(std::string(control) + ": the cycle runs in mode '" + mode +
                         "'; only the automatic task (mode 'auto') takes the operator's controls");
    return *cycle->task();
  }
};

double seconds_arg(py::handle v, const char* name) {
  if (py::isinstance<py::bool_>(v) || !(py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v)))
    throw py::type_error(std::string(name) + ": expected a number of seconds (got " + given(v) + ")");
  const double s = v.cast<double>();
  if (!std::isfinite(s) || s < 0.0)
    throw InvalidInput(std::string(name) + ": " + py::repr(v).cast<std::string>() +
                       " is not a duration (finite, >= 0 s)");
  return s;
}

py::dict job_dict(const cl::AssemblyJob& j) {
  return py::dict("index"_a = j.index, "side_m"_a = j.side_m, "clearance_m"_a = j.clearance_m,
                  "nominal_part_m"_a = py::make_tuple(j.nominal_part_m.x(), j.nominal_part_m.y()),
                  "target_m"_a = py::make_tuple(j.target_m.x(), j.target_m.y()));
}

}  // namespace

void bind_cell(py::module_& m) {
  m.def("modes", &cl::cell_modes, "The modes a batch runs in (the library's list: auto, manual, ...).");
  m.def(
      "params",
      [] {
        return py::dict("scene"_a = params_dict(cl::AssemblyBatchParams{}),
                        "run"_a = params_dict(cl::CellRunParams{}));
      },
      "The default scene and run parameters, as `microcobot cell params --json`:\n"
      "{'scene': AssemblyBatchParams keys, 'run': CellRunParams keys}.");
  m.def(
      "run_params",
      [](py::handle params, py::handle mode) { return params_dict(run_params_from(params, mode)); },
      "params"_a = py::none(), "mode"_a = py::none(),
      "The complete, validated run parameters: `params` (None, a dict of overrides or a YAML file, as\n"
      "`cell run --params`) with `mode` over them. ValueError names a bad key or mode.");
  m.def(
      "summarize",
      [](const py::list& cycles) {
        if (cycles.empty()) throw InvalidInput("cycles: an empty list (summarize needs at least one cycle)");
        std::vector<cl::CycleResult> results;
        for (std::size_t i = 0; i < cycles.size(); ++i) {
          const std::string where = "cycles[" + std::to_string(i) + "]";
          if (!py::isinstance<py::dict>(cycles[i]))
            throw py::type_error(where + ": expected a dict (got " + given(cycles[i]) + ")");
          try {
            results.push_back(cl::CycleResult::from_json(to_json_value(cycles[i], where)));
          } catch (const InvalidInput& e) {
            throw InvalidInput(where + ": " + e.what());
          }
        }
        return from_json(cl::summarize(results).to_json());
      },
      "cycles"_a,
      "The summary of cycle results (dicts as run() returns them), as `microcobot cell run --json`:\n"
      "cycles, successes, success rate with its 95 % Wilson interval, cycle time median and IQR,\n"
      "placement median, peak forces, ticks over a force limit, simulated and wall time.");

  py::class_<Batch>(
      m, "Batch",
      "A batch of pin insertions (`microcobot cell run --scene --batch --seed`): the parts a\n"
      "seeded scene gives, each run on a fresh simulated platform. The same scene and seed give\n"
      "the same parts and the same results.")
      .def(py::init<py::handle, py::handle, py::handle>(), "scene"_a = py::none(), "parts"_a = py::none(),
           "seed"_a = py::none(),
           "scene: None (the defaults), a dict of AssemblyBatchParams keys or a YAML file (as --scene);\n"
           "parts (as --batch) and seed (as --seed) over it. ValueError names a bad key or value.")
      .def("__len__", [](const Batch& b) { return b.jobs.size(); })
      .def_property_readonly(
          "scene", [](const Batch& b) { return params_dict(b.scene); },
          "The complete scene parameters (a dict that Batch(scene=...) takes back).")
      .def_property_readonly(
          "jobs",
          [](const Batch& b) {
            py::list l;
            for (const auto& j : b.jobs) l.append(job_dict(j));
            return l;
          },
          "Each part as the cell is told it: index, side_m, clearance_m, nominal_part_m, target_m.")
      .def(
          "run_cycle",
          [](const Batch& b, py::handle index, py::handle mode, py::handle params, py::handle config) {
            const cl::AssemblyJob& job = b.job(index);
            const cl::CellRunParams p = run_params_from(params, mode);
            platform::PlatformConfig c = config_from(config);
            const cl::CycleResult r = nogil([&] { return cl::run_cycle(job, p, std::move(c)); });
            return from_json(r.to_json());
          },
          "index"_a, "mode"_a = py::none(), "params"_a = py::none(), "config"_a = py::none(),
          "Runs part `index` to its end in `mode` (a str: 'auto', 'manual', ... as modes() lists; None:\n"
          "the params' mode), with `params` (run parameters, as run_params) on the platform `config`\n"
          "(None, dict or YAML file, as --config). Returns its result dict (CycleResult). The GIL is\n"
          "released while it simulates.")
      .def(
          "run",
          [](const Batch& b, py::handle mode, py::handle params, py::handle config, py::handle indices) {
            const cl::CellRunParams p = run_params_from(params, mode);
            const platform::PlatformConfig c = config_from(config);
            std::vector<cl::AssemblyJob> jobs;
            if (indices.is_none()) {
              jobs = b.jobs;
            } else {
              if (!py::isinstance<py::sequence>(indices) || py::isinstance<py::str>(indices))
                throw py::type_error("indices: expected a list of ints (got " + given(indices) + ")");
              for (const auto& i : indices) jobs.push_back(b.job(i));
            }
            const auto results = nogil([&] { return cl::run_batch(jobs, p, c); });
            py::list out;
            for (const auto& r : results) out.append(from_json(r.to_json()));
            return out;
          },
          "mode"_a = py::none(), "params"_a = py::none(), "config"_a = py::none(), "indices"_a = py::none(),
          "Runs every part in order (or the parts `indices`) as run_cycle does; a list of result dicts,\n"
          "the cycles of `microcobot cell run --json` ('cycles_detail'). The GIL is released.")
      .def(py::pickle([](const Batch& b) { return params_dict(b.scene); },
                      [](const py::dict& scene) { return Batch(scene, py::none(), py::none()); }));

  py::class_<Cycle>(
      m, "Cycle",
      "One part's cycle on its own simulated platform, stepped from Python (a task from Python): run it\n"
      "for a while, look at its step and status, pause, resume, confirm, take over, hand back, skip,\n"
      "then run on. The same part, mode and parameters give the same cycle as Batch.run_cycle.")
      .def(py::init([](py::handle batch, py::handle index, py::handle mode, py::handle params,
                       py::handle config, py::handle task) {
             if (!py::isinstance<Batch>(batch))
               throw py::type_error("batch: expected a cell.Batch (got " + given(batch) + ")");
             const Batch& b = batch.cast<const Batch&>();
             const cl::AssemblyJob& job = b.job(index);
             cl::CellRunParams p = run_params_from(params, mode);
             apply_task(task, p);
             p.validate();
             platform::PlatformConfig c = config_from(config);
             Cycle out;
             out.mode = p.mode;
             out.cycle = nogil([&] { return std::make_unique<cl::CellCycle>(job, p, std::move(c)); });
             return out;
           }),
           "batch"_a, "index"_a, "mode"_a = py::none(), "params"_a = py::none(), "config"_a = py::none(),
           "task"_a = py::none(),
           "Part `index` of `batch` in `mode` with `params` on the platform `config`, as Batch.run_cycle;\n"
           "`task`: None, a dict or a YAML file as `cell run --task` ({'steps': {'insert': 'confirm'},\n"
           "'params': {...}}). ValueError names a bad key, value or step.")
      .def(
          "run_for",
          [](Cycle& c, py::handle seconds) {
            const double s = seconds_arg(seconds, "seconds");
            c.run("run_for", [&] { c.cycle->run_for(s); });
          },
          "seconds"_a,
          "Simulates `seconds` more (or to the cycle's end, or to max_cycle_s). The GIL is released.")
      .def(
          "run_to_end", [](Cycle& c) { c.run("run_to_end", [&] { c.cycle->run_to_end(); }); },
          "Simulates to the cycle's end (or to max_cycle_s).")
      .def_property_readonly(
          "finished", [](Cycle& c) { return c.idle("finished").finished(); },
          "The task (or the person) is done.")
      .def_property_readonly(
          "time_s", [](Cycle& c) { return c.idle("time_s").platform().loop().time_s(); },
          "Simulated time [s].")
      .def_property_readonly(
          "step",
          [](Cycle& c) {
            c.idle("step");
            if (c.cycle->task()) return std::string(cl::AssemblyTask::name(c.cycle->task()->step()));
            if (c.cycle->person()) return std::string(cl::AssemblyTask::name(c.cycle->person()->step()));
            return std::string();
          },
          "The current step ('approach', 'align', ... 'rotate', ... 'verify', 'done'); '' for the scripted\n"
          "watchmaker.")
      .def_property_readonly(
          "status",
          [](Cycle& c) {
            c.idle("status");
            if (c.cycle->task()) return std::string(cl::AssemblyTask::name(c.cycle->task()->status()));
            return std::string(c.cycle->finished() ? "finished" : "running");
          },
          "The task's status: 'running', 'paused', 'awaiting confirmation', 'operator', 'succeeded',\n"
          "'failed' (other modes: 'running' or 'finished').")
      .def_property_readonly(
          "tip_m",
          [](Cycle& c) {
            platform::Platform& p = c.idle("tip_m").platform();
            return py::make_tuple(p.axis(0).position_m(), p.axis(1).position_m(), p.axis(2).position_m());
          },
          "The stage's measured position (x, y, z) [m], relative to its home.")
      .def_property_readonly(
          "yaw_rad", [](Cycle& c) { return c.idle("yaw_rad").platform().yaw_rad(); },
          "The rotary axis' measured angle, the fingers' yaw [rad] (align and rotate turn it).")
      .def(
          "pause", [](Cycle& c) { c.task("pause").pause(); },
          "The task lets the deadman go: the stage holds from the next tick until resume().")
      .def(
          "resume", [](Cycle& c) { c.task("resume").resume(); }, "Goes on from where the stage is.")
      .def(
          "confirm", [](Cycle& c) { c.task("confirm").confirm(); },
          "Starts a step that awaits confirmation (autonomy 'confirm'; headless, the supervisor confirms\n"
          "it after params' confirm_delay_s otherwise).")
      .def(
          "take_over", [](Cycle& c) { c.task("take_over").take_over(); },
          "The operator takes the stage: the task sends nothing (headless, nothing drives: it holds).")
      .def(
          "hand_back",
          [](Cycle& c, py::handle step_done) {
            if (!py::isinstance<py::bool_>(step_done))
              throw py::type_error("step_done: expected a bool (got " + given(step_done) + ")");
            c.task("hand_back").hand_back(step_done.cast<bool>());
          },
          "step_done"_a = false,
          "The task goes on: the current step again from where the stage is, or with step_done the next.")
      .def(
          "skip", [](Cycle& c) { c.task("skip").skip(); }, "Leaves the current step for the next one.")
      .def(
          "result", [](Cycle& c) { return from_json(c.idle("result").result().to_json()); },
          "The cycle's result dict (CycleResult), as Batch.run_cycle returns it; complete once finished.");
}

}  // namespace mc::py

// SPDX-License-Identifier: GPL-3.0-or-later
// The Python module asperity._asperity (docs/python.md): thin bindings of the C++ library, one
// translation unit. No physics here: every number comes from the library; this file converts
// arguments (numpy arrays, dicts, callables) and results, releases the GIL while the library
// computes, and turns Ctrl-C into KeyboardInterrupt through the progress path.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <toml++/toml.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "asperity/app/cor_table.hpp"
#include "asperity/app/plan.hpp"
#include "asperity/app/resources.hpp"
#include "asperity/app/run.hpp"
#include "asperity/app/scene.hpp"
#include "asperity/app/scene_file.hpp"
#include "asperity/config.hpp"
#include "asperity/core/contact.hpp"
#include "asperity/core/geometry.hpp"
#include "asperity/core/impact.hpp"
#include "asperity/core/orientation.hpp"
#include "asperity/core/restitution.hpp"
#include "asperity/experiments/ensemble.hpp"
#include "asperity/laws/theory.hpp"
#include "asperity/laws/theory_impact.hpp"

namespace py = pybind11;
using namespace asperity;

namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

[[noreturn]] void value_error(const std::string& what) { throw py::value_error(what); }
// A parameter of the wrong type: TypeError naming it (pybind11's own names no parameter).
[[noreturn]] void type_error(const std::string& what) { throw py::type_error(what); }

// Signatures in Python's types. pybind11 writes a parameter taken as py::handle/py::object as
// `handle`/`object` and a class registered later by its C++ name; for those defs it writes no
// signature (a scoped PythonSignatures) and the docstring begins with the one written here, in the
// stub's types (src/python/_asperity.pyi; tests/python/test_stubs.py compares the two).
struct PythonSignatures {
  py::options options;
  PythonSignatures() { options.disable_function_signatures(); }
};
constexpr const char* kSceneType = "str | os.PathLike[str] | Mapping[str, Any]";

// The library's range checks name the CLI's flags (asperity-radius); Python's parameters are
// spelled with underscores (asperity_radius).
template <class F>
auto python_names(F&& f) {
  try {
    return f();
  } catch (const std::invalid_argument& e) {
    std::string m = e.what();
    for (std::size_t i = m.find("asperity-radius"); i != std::string::npos; i = m.find("asperity-radius", i)) m[i + 8] = '_';
    value_error(m);
  }
}

std::string show(const py::handle& h) { return py::repr(h).cast<std::string>(); }

// An array of doubles from `obj`, or TypeError naming the parameter: numpy's own refusal (a string,
// an object) names nothing. `what` describes what is expected.
Doubles doubles(const py::handle& obj, const std::string& name, const std::string& what) {
  if (py::isinstance<py::str>(obj) || py::isinstance<py::bytes>(obj) || obj.is_none())
    type_error(name + ": expected " + what + ", got " + show(obj));
  try {
    return py::cast<Doubles>(obj);
  } catch (const py::cast_error&) {
  } catch (const py::error_already_set&) {
  }
  type_error(name + ": expected " + what + ", got " + show(obj));
}

// A std::vector moved into a numpy array without a copy: the capsule owns it.
template <class T>
py::array_t<T> to_numpy(std::vector<T>&& v) {
  auto* owner = new std::vector<T>(std::move(v));
  py::capsule free(owner, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>({static_cast<py::ssize_t>(owner->size())}, {static_cast<py::ssize_t>(sizeof(T))}, owner->data(), free);
}

py::array_t<bool> to_numpy_bool(const std::vector<std::uint8_t>& v) {
  py::array_t<bool> a(static_cast<py::ssize_t>(v.size()));
  auto m = a.mutable_unchecked<1>();
  for (std::size_t i = 0; i < v.size(); ++i) m(static_cast<py::ssize_t>(i)) = v[i] != 0;
  return a;
}

// An (M, 3) array of vectors, or one vector of shape (3,) (then M = 1 and `single` is set).
struct Vectors {
  std::vector<Vec3> v;
  bool single = false;
};

Vectors vectors(const py::handle& obj, const char* name) {
  const Doubles a = doubles(obj, name, "an array of shape (M, 3) or (3,)");
  Vectors out;
  if (a.ndim() == 1 && a.shape(0) == 3) {
    out.single = true;
    out.v.emplace_back(a.at(0), a.at(1), a.at(2));
  } else if (a.ndim() == 2 && a.shape(1) == 3) {
    const auto r = a.unchecked<2>();
    out.v.resize(static_cast<std::size_t>(a.shape(0)));
    for (py::ssize_t i = 0; i < a.shape(0); ++i) out.v[static_cast<std::size_t>(i)] = Vec3(r(i, 0), r(i, 1), r(i, 2));
  } else {
    std::ostringstream s;
    s << name << ": expected shape (M, 3) or (3,), got shape (";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) s << (i ? ", " : "") << a.shape(i);
    s << (a.ndim() == 1 ? ",)" : ")");
    value_error(s.str());
  }
  for (std::size_t i = 0; i < out.v.size(); ++i)
    if (!out.v[i].allFinite()) {
      std::ostringstream s;
      s << name << "[" << i << "] = (" << out.v[i].x() << ", " << out.v[i].y() << ", " << out.v[i].z() << "): not finite";
      value_error(s.str());
    }
  return out;
}

py::array_t<double> vectors_to_numpy(const std::vector<Vec3>& v, bool single) {
  if (single) {
    py::array_t<double> a(3);
    for (int k = 0; k < 3; ++k) a.mutable_at(k) = v.at(0)[k];
    return a;
  }
  py::array_t<double> a({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
  auto m = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int k = 0; k < 3; ++k) m(static_cast<py::ssize_t>(i), k) = v[i][k];
  return a;
}

// ---- scenes: a path, a preset name, or a dict in the scene-file layout ----

// A str as its UTF-8 bytes, or ValueError naming the parameter: a lone surrogate ('\\ud800') cannot
// be encoded, and pybind11's own cast says "Unable to cast ..." without naming anything.
std::string utf8_string(const py::handle& h, const std::string& name) {
  Py_ssize_t n = 0;
  const char* p = PyUnicode_AsUTF8AndSize(h.ptr(), &n);
  if (p == nullptr) {
    PyErr_Clear();
    value_error(name + " = " + show(h) + ": cannot be encoded as UTF-8 (a lone surrogate)");
  }
  return std::string(p, static_cast<std::size_t>(n));
}

// A path (str, bytes or os.PathLike) as the bytes the file system sees, as open() takes it
// (os.fsencode): a PathLike whose __fspath__ returns bytes is those bytes, not the text "b'...'".
std::string path_bytes(const py::handle& h, const std::string& name) {
  try {
    return py::module_::import("os").attr("fsencode")(h).cast<std::string>();
  } catch (py::error_already_set& e) {
    if (e.matches(PyExc_UnicodeError)) value_error(name + " = " + show(h) + ": cannot be encoded as a file name (a lone surrogate)");
    if (e.matches(PyExc_TypeError)) type_error(name + ": expected a path (str, bytes or os.PathLike), got " + show(h));
    throw;
  }
}

bool is_path(const py::handle& h) {
  return py::isinstance<py::str>(h) || py::isinstance<py::bytes>(h) || py::hasattr(h, "__fspath__");
}

// True and False, numpy's too (numpy.bool_: no int, though it once had __index__).
bool is_bool(const py::handle& h) {
  if (py::isinstance<py::bool_>(h)) return true;
  const std::string t = py::type::of(h).attr("__name__").cast<std::string>();
  return (t == "bool_" || t == "bool") && py::type::of(h).attr("__module__").cast<std::string>() == "numpy";
}

// operator.index(h) (Python and numpy integers), or the TypeError it raised.
py::int_ index_of(const py::handle& h) {
  PyObject* i = PyNumber_Index(h.ptr());
  if (i == nullptr) throw py::error_already_set();
  return py::reinterpret_steal<py::int_>(i);
}

// A scalar (bool, int, float, str, numpy scalar) handed to sink; false for anything else. `key`
// names it in errors.
template <class Sink>
bool toml_scalar(const py::handle& h, const std::string& key, Sink sink) {
  if (is_bool(h)) return sink(PyObject_IsTrue(h.ptr()) == 1), true;
  if (py::isinstance<py::dict>(h) || py::isinstance<py::list>(h) || py::isinstance<py::tuple>(h) || py::isinstance<py::array>(h))
    return false;
  if (py::isinstance<py::int_>(h) || (!py::isinstance<py::float_>(h) && !py::isinstance<py::str>(h) && py::hasattr(h, "__index__"))) {
    // Python and numpy integers alike (numpy.uint64 too). TOML integers are 64-bit signed: a
    // seed in [2^63, 2^64 - 1] is written as its digits (the scene reader takes a seed as a
    // string of digits); anything larger is out of every range the scene checks.
    const py::int_ o = index_of(h);
    if (o >= py::int_(std::numeric_limits<std::int64_t>::min()) && o <= py::int_(std::numeric_limits<std::int64_t>::max()))
      return sink(o.cast<std::int64_t>()), true;
    if (o > py::int_(0) && o <= py::int_(std::numeric_limits<std::uint64_t>::max())) return sink(std::to_string(o.cast<std::uint64_t>())), true;
    return sink(o.cast<double>()), true;
  }
  if (py::isinstance<py::float_>(h)) return sink(h.cast<double>()), true;
  if (py::isinstance<py::str>(h)) return sink(utf8_string(h, "scene dict: " + key)), true;
  const auto o = py::reinterpret_borrow<py::object>(h);
  if (py::hasattr(h, "__float__")) return sink(py::float_(o).cast<double>()), true;  // numpy floats
  return false;
}

bool is_sequence(const py::handle& h) {
  return py::isinstance<py::list>(h) || py::isinstance<py::tuple>(h) || py::isinstance<py::array>(h);
}

// The dict/list nesting allowed in a scene dict: the scene reader's limit (scene_file.cpp
// kMaxNesting: arrays or inline tables at most 16 deep; a dotted key at most 16 parts). Checked
// before recursing, so a dict that contains itself or a list nested 10^5 deep is a ValueError,
// not a stack overflow. `path` holds the containers being converted, to name a cycle as one.
constexpr std::size_t kMaxSceneDictNesting = 16;

struct Nesting {
  std::vector<const PyObject*> path;
  void enter(const py::handle& h, const std::string& key) {
    for (const PyObject* p : path)
      if (p == h.ptr()) value_error("scene dict: " + (key.empty() ? std::string("the dict") : key) + " contains itself (a cycle)");
    if (path.size() >= kMaxSceneDictNesting)
      value_error("scene dict: " + key + ": dicts and lists nested more than " + std::to_string(kMaxSceneDictNesting) +
                  " deep (the scene reader's limit)");
    path.push_back(h.ptr());
  }
  void leave() { path.pop_back(); }
};

toml::table to_toml_table(const py::dict& d, const std::string& key, Nesting& nest);

toml::array to_toml_array(const py::handle& h, const std::string& key, Nesting& nest) {
  nest.enter(h, key);
  toml::array a;
  py::list l = py::isinstance<py::array>(h) ? py::list(h.attr("tolist")()) : py::list(py::reinterpret_borrow<py::object>(h));
  for (std::size_t i = 0; i < l.size(); ++i) {
    const std::string k = key + "[" + std::to_string(i) + "]";
    const py::handle v = l[i];
    if (toml_scalar(v, k, [&](auto&& x) { a.push_back(std::forward<decltype(x)>(x)); })) continue;
    if (py::isinstance<py::dict>(v)) a.push_back(to_toml_table(v.cast<py::dict>(), k, nest));
    else if (is_sequence(v)) a.push_back(to_toml_array(v, k, nest));
    else value_error("scene dict: " + k + " = " + show(v) + ": not a bool, number, string, list or dict");
  }
  nest.leave();
  return a;
}

toml::table to_toml_table(const py::dict& d, const std::string& key, Nesting& nest) {
  nest.enter(d, key);
  toml::table t;
  for (const auto& [k, v] : d) {
    if (!py::isinstance<py::str>(k)) value_error("scene dict: key " + show(k) + (key.empty() ? "" : " in " + key) + " is not a string");
    const std::string name = utf8_string(k, "scene dict: a key" + (key.empty() ? std::string() : " in " + key));
    const std::string full = key.empty() ? name : key + "." + name;
    if (v.is_none()) continue;  // None: the key is absent (its default)
    if (toml_scalar(v, full, [&](auto&& x) { t.insert(name, std::forward<decltype(x)>(x)); })) continue;
    if (py::isinstance<py::dict>(v)) t.insert(name, to_toml_table(v.cast<py::dict>(), full, nest));
    else if (is_sequence(v)) t.insert(name, to_toml_array(v, full, nest));
    else value_error("scene dict: " + full + " = " + show(v) + ": not a bool, number, string, list or dict");
  }
  nest.leave();
  return t;
}

std::string dict_to_toml(const py::dict& d) {
  Nesting nest;
  toml::table t = to_toml_table(d, "", nest);
  if (!t.contains("format")) t.insert("format", std::int64_t{kSceneFormatVersion});
  std::ostringstream s;
  s << t;
  return s.str();
}

// SceneError and every other std::invalid_argument become ValueError (pybind11's translation).
Scene to_scene(const py::handle& scene) {
  if (py::isinstance<py::dict>(scene)) return parse_scene(dict_to_toml(scene.cast<py::dict>()), "scene dict");
  if (is_path(scene)) {
    const std::string s = path_bytes(scene, "scene");
    std::error_code ec;
    if (std::filesystem::is_regular_file(s, ec)) return load_scene(s);
    for (const auto& p : preset_names())
      if (p == s) return preset(s);
    std::string names;
    for (const auto& p : preset_names()) names += (names.empty() ? "" : ", ") + p;
    value_error("scene: '" + s + "' is neither a scene file nor a preset (" + names + ")");
  }
  type_error("scene: expected a path, a preset name or a dict, got " + show(scene));
}

// The progress path of every long call: runs with the GIL released; every report takes the GIL,
// checks for signals (Ctrl-C -> KeyboardInterrupt) and calls the user's callable. An exception
// thrown here stops the library's loops and comes out of the call (ensemble.cpp GuardedProgress).
// The callable is held through a shared_ptr: copies of the Progress (made without the GIL) touch no
// Python reference count; the last copy dies in the caller, with the GIL held.
Progress python_progress(const py::object& callback) {
  auto held = std::make_shared<py::object>(callback);
  return [held](std::uint64_t done, std::uint64_t total) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!held->is_none()) (*held)(done, total);
  };
}

void check_callable(const py::object& progress) {
  if (!progress.is_none() && !PyCallable_Check(progress.ptr())) type_error("progress: expected a callable or None, got " + show(progress));
}

// ---- run ----

py::dict samples_to_dict(ContactSamples&& s) {
  py::dict d;
  d["r_x"] = to_numpy(std::move(s.r_x));
  d["r_y"] = to_numpy(std::move(s.r_y));
  d["r_z"] = to_numpy(std::move(s.r_z));
  d["r_xy"] = to_numpy(std::move(s.r_xy));
  d["gap"] = to_numpy(std::move(s.gap));
  d["core"] = to_numpy_bool(s.core);
  if (!s.eps.empty() || !s.eps_core.empty()) {
    d["eps"] = to_numpy(std::move(s.eps));
    d["omega_x_after"] = to_numpy(std::move(s.omega_x_after));
    d["eps_n"] = to_numpy(std::move(s.eps_n));
    d["eps_core"] = to_numpy_bool(s.eps_core);
  }
  return d;
}

// Where asperity.run may write (out=): None (the default) writes no file at all -- no figures, no
// checkpoints -- and refuses a scene whose outputs are files (a notebook must not litter its working
// directory); a path writes the scene's outputs there; True writes them to the scene's outputs.dir.
// Returns whether files are written.
bool apply_out(Scene& scene, RunControl& control, const py::object& out) {
  if (out.is_none() || (py::isinstance<py::bool_>(out) && !out.cast<bool>())) {
    if (const std::string key = file_output_key(scene); !key.empty())
      value_error("out: the scene's " + key + " writes a file; pass out=DIR (or out=True for the scene's outputs.dir)");
    scene.plots = false;
    control.checkpoint_seconds = 0;  // no signal handler in Python: never written
    return false;
  }
  if (py::isinstance<py::bool_>(out)) return true;  // True: the scene's outputs.dir
  if (!is_path(out)) type_error("out: expected None, True, False or a directory path, got " + show(out));
  scene.out = path_bytes(out, "out");
  if (scene.out.empty()) value_error("out: '' is not a directory name");
  return true;
}

py::object run(const py::handle& scene_arg, const py::object& progress, const py::object& arrays_arg, std::uint64_t max_array_drops,
               const py::object& out_arg) {
  check_callable(progress);
  Scene scene = to_scene(scene_arg);
  RunControl control;
  apply_out(scene, control, out_arg);
  bool arrays = false;
  if (arrays_arg.is_none())
    arrays = run_kind(scene) == RunKind::sphere && scene.ensemble.drops <= max_array_drops;
  else if (!py::isinstance<py::bool_>(arrays_arg))
    type_error("arrays: expected None, True or False, got " + show(arrays_arg));
  else if (arrays_arg.cast<bool>()) {
    if (run_kind(scene) != RunKind::sphere)
      value_error("arrays: per-drop arrays exist for sphere scenes only, not for a " + std::string(to_string(run_kind(scene))) + " scene");
    arrays = true;
  }
  const Plan planned = plan(std::move(scene), control);  // the run's one plan
  if (arrays) {  // the arrays' pass keeps every drop: its estimate is the raw run's
    Plan raw = planned;
    raw.scene.ensemble.statistics = raw.given.ensemble.statistics = Statistics::raw;
    raw.streams = false;
    check_memory(raw);
  }
  const Progress p = python_progress(progress);
  SceneOutput out;
  ContactSamples samples;
  {
    py::gil_scoped_release nogil;
    // The arrays are the run's own drops; a streaming run keeps none, so its arrays come from the
    // same drops again, bit-identical (every drop is a pure function of seed and index).
    // out=None: the plan writes no file (apply_out), so run_plan touches no directory.
    out = run_plan(planned, p, nullptr, {}, nullptr,
                   arrays && !planned.streams ? &samples : nullptr);
    if (arrays && planned.streams) samples = run_contact_ensemble(planned.scene.ensemble, p);
  }
  py::dict report = py::module_::import("json").attr("loads")(out.json);
  if (arrays) report["arrays"] = samples_to_dict(std::move(samples));
  return report;
}

// ---- rough spheres and contact queries ----

struct PySphere {
  RoughSphere body;
};

struct PyQuery {
  std::shared_ptr<PySphere> sphere;  // the index points into sphere->body.centres
  std::unique_ptr<ContactQuery> index;
};

py::dict nearest_to_dict(const std::vector<Nearest>& n, bool single) {
  std::vector<std::uint32_t> idx(n.size()), run(n.size());
  std::vector<double> key(n.size()), rkey(n.size());
  for (std::size_t i = 0; i < n.size(); ++i) idx[i] = n[i].index, key[i] = n[i].key, run[i] = n[i].runner_up, rkey[i] = n[i].runner_up_key;
  py::dict d;
  if (single) {
    d["index"] = idx[0], d["key"] = key[0], d["runner_up"] = run[0], d["runner_up_key"] = rkey[0];
  } else {
    d["index"] = to_numpy(std::move(idx)), d["key"] = to_numpy(std::move(key));
    d["runner_up"] = to_numpy(std::move(run)), d["runner_up_key"] = to_numpy(std::move(rkey));
  }
  return d;
}

void check_unit(const std::vector<Vec3>& d, const char* name) {
  for (std::size_t i = 0; i < d.size(); ++i)
    if (std::abs(d[i].norm() - 1.0) > 1e-9) {
      std::ostringstream s;
      s << name << "[" << i << "] = (" << d[i].x() << ", " << d[i].y() << ", " << d[i].z() << "): not a unit vector (|d| = " << d[i].norm() << ")";
      value_error(s.str());
    }
}

std::vector<Rotation> quaternions(const py::handle& obj, bool& single) {
  const Doubles a = doubles(obj, "q", "quaternions (w, x, y, z) of shape (M, 4) or (4,)");
  single = a.ndim() == 1;
  if (!((a.ndim() == 1 && a.shape(0) == 4) || (a.ndim() == 2 && a.shape(1) == 4)))
    value_error("q: expected quaternions (w, x, y, z) of shape (M, 4) or (4,), got an array of " + std::to_string(a.ndim()) + " dimensions");
  const py::ssize_t m = single ? 1 : a.shape(0);
  const double* p = a.data();
  std::vector<Rotation> q;
  for (py::ssize_t i = 0; i < m; ++i) {
    Rotation r(p[4 * i], p[4 * i + 1], p[4 * i + 2], p[4 * i + 3]);
    const double n = r.norm();
    if (!std::isfinite(n) || std::abs(n - 1.0) > 1e-9)
      value_error("q[" + std::to_string(i) + "]: not a unit quaternion (|q| = " + std::to_string(n) + ")");
    q.push_back(r);
  }
  return q;
}

// ---- restitution models ----

std::shared_ptr<Restitution> restitution_model(const py::handle& h) {
  if (py::isinstance<Restitution>(h)) return h.cast<std::shared_ptr<Restitution>>();
  if (py::isinstance<py::float_>(h) || py::isinstance<py::int_>(h)) {
    const double e = h.cast<double>();
    if (!(e >= 0 && e <= 1)) value_error("eps_n = " + show(h) + ": must be in [0, 1]");
    return constant_restitution(e);
  }
  type_error("eps_n: expected a number in [0, 1] or a restitution model (asperity.pade14, asperity.constant), got " + show(h));
}

// Evaluates a scalar function of the library elementwise over an array (GIL released), keeping
// the input's shape; a Python float in, a float out.
template <class F>
py::object elementwise(const py::handle& x, F f, const char* name = "x") {
  if (py::isinstance<py::float_>(x) || py::isinstance<py::int_>(x)) return py::float_(f(x.cast<double>()));
  const Doubles a = doubles(x, name, "a number or an array of numbers");
  std::vector<py::ssize_t> shape(a.shape(), a.shape() + a.ndim());
  py::array_t<double> out(shape);
  const double* in = a.data();
  double* o = out.mutable_data();
  const auto n = static_cast<std::size_t>(a.size());
  {
    py::gil_scoped_release nogil;
    for (std::size_t i = 0; i < n; ++i) o[i] = f(in[i]);
  }
  return out;
}

ImpactScene impact_scene(std::uint64_t n, double R, double a, double speed, double omega_x, double omega_y, double beta, bool core) {
  ImpactScene s;
  s.asperities = n, s.radius = R, s.asperity_radius = a, s.speed = speed, s.omega_x = omega_x, s.omega_y = omega_y;
  s.beta = beta, s.core_contacts = core;
  return s;
}

// One function per group of bindings, in the order the module defines them.
void bind_scenes_and_runs(py::module_& m) {
  m.def("presets", &preset_names, "Names of the built-in preset scenes.");
  m.def("preset_text", [](const std::string& name) { return std::string(preset_text(name)); }, py::arg("name"),
        "The TOML text of a preset scene.");
  const PythonSignatures signatures;
  m.def("scene_toml", [](const py::handle& scene) { return to_toml(to_scene(scene)); }, py::arg("scene"),
        (std::string("scene_toml(scene: ") + kSceneType +
         ") -> str\n\nThe effective scene (path, preset name or dict) as a format-1 TOML document.").c_str());
  m.def("run", &run, py::arg("scene"), py::arg("progress") = py::none(), py::arg("arrays") = py::none(),
        py::arg("max_array_drops") = std::uint64_t{2000000}, py::arg("out") = py::none(),
        (std::string("run(scene: ") + kSceneType +
         ", progress: Callable[[int, int], Any] | None = None, arrays: bool | None = None, max_array_drops: int = 2000000, "
         "out: str | os.PathLike[str] | bool | None = None) -> dict[str, Any]\n\n" + R"doc(Runs a scene as validate-geometry does and returns report.json as a dict.

scene: a scene file path, a preset name (asperity.presets()) or a dict in the scene-file layout.
progress: None or a callable progress(done, total), called from this thread now and then.
arrays: None (default) adds report["arrays"] (per-drop numpy arrays r_x, r_y, r_z, r_xy, gap,
  core, and for impacts eps, omega_x_after, eps_n, eps_core) for sphere scenes of at most
  max_array_drops drops; True/False forces. The arrays are the run's drops recomputed from the
  same seed (bit-identical), which costs a second pass over the ensemble.
out: None (default) writes no file at all (no figures, no checkpoints; a scene whose outputs are
  files -- outputs.cor_table, body.export_ply -- is refused); a directory path writes the figures and
  the scene's output files there, as the CLI would (the report file is not written: it is the
  return value); True writes them to the scene's outputs.dir.
The GIL is released while the run computes; Ctrl-C raises KeyboardInterrupt.)doc").c_str());
}

void bind_spheres(py::module_& m) {
  const PythonSignatures signatures;  // query's signature names ContactQuery, registered later
  py::class_<PySphere, std::shared_ptr<PySphere>>(m, "RoughSphere", "An explicit rough sphere (core/geometry.hpp).")
      .def_property_readonly("asperities", [](const PySphere& s) { return s.body.params.asperities; })
      .def_property_readonly("radius", [](const PySphere& s) { return s.body.params.radius; })
      .def_property_readonly("asperity_radius", [](const PySphere& s) { return s.body.params.asperity_radius; })
      .def("__len__", [](const PySphere& s) { return s.body.centres.size(); }, "__len__(self: RoughSphere) -> int\n\nN, the number of asperities.")
      .def_property_readonly(
          "centres",
          [](py::object self) {
            auto& s = self.cast<PySphere&>();
            static_assert(sizeof(Vec3) == 3 * sizeof(double));
            py::array_t<double> a({static_cast<py::ssize_t>(s.body.centres.size()), py::ssize_t{3}},
                                  {static_cast<py::ssize_t>(sizeof(Vec3)), static_cast<py::ssize_t>(sizeof(double))},
                                  s.body.centres.empty() ? nullptr : s.body.centres.front().data(), self);
            py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
            return a;
          },
          "Unit asperity centres u_i, shape (N, 3): a read-only view of the sphere's memory (no copy; keeps the sphere alive). "
          "Centre i is at R u_i.")
      .def(
          "query",
          [](std::shared_ptr<PySphere> self, const std::string& backend) {
            auto q = std::make_shared<PyQuery>();
            q->sphere = self;
            const Backend b = parse_backend(backend);
            const std::uint64_t n = self->body.centres.size();
            check_bytes(sphere_bytes(n, b) - sphere_bytes(n, Backend::brute),
                        "a " + std::string(to_string(b)) + " index over " + std::to_string(n) + " asperities", "the sphere's asperities");
            py::gil_scoped_release nogil;
            q->index = make_contact_query(b, self->body.centres);
            return q;
          },
          py::arg("backend") = "grid",
          "query(self: RoughSphere, backend: str = 'grid') -> ContactQuery\n\n"
          "A contact query index over the centres: backend is one of asperity.backends() (brute, kdtree, cgal, fcl, grid).");
  m.def(
      "make_rough_sphere",
      [](std::uint64_t n, double R, double a, std::uint64_t seed, std::uint64_t sphere_id) {
        SphereParams p;
        p.asperities = n, p.radius = R, p.asperity_radius = a;
        python_names([&] { validate(p); });
        check_bytes(sphere_bytes(n, Backend::brute), std::to_string(n) + " asperity centres x 24 B", "asperities");
        auto s = std::make_shared<PySphere>();
        py::gil_scoped_release nogil;
        s->body = make_rough_sphere(p, seed, sphere_id);
        return s;
      },
      py::arg("asperities") = 100000, py::arg("radius") = 3e-3, py::arg("asperity_radius") = 6.5e-7, py::arg("seed") = 1,
      py::arg("sphere_id") = 0,
      "make_rough_sphere(asperities: int = 100000, radius: float = 0.003, asperity_radius: float = 6.5e-07, seed: int = 1, "
      "sphere_id: int = 0) -> RoughSphere\n\n"
      "N asperity centres uniform on the sphere of radius R [m], each asperity of radius asperity_radius [m]: a pure "
      "function of (seed, sphere_id).");
}

void bind_queries(py::module_& m) {
  const PythonSignatures signatures;
  py::class_<PyQuery, std::shared_ptr<PyQuery>>(m, "ContactQuery",
                                                "A contact query index over a RoughSphere's centres (RoughSphere.query()).")
      .def_property_readonly("backend", [](const PyQuery& q) { return std::string(to_string(q.index->backend())); })
      .def_property_readonly("memory_bytes", [](const PyQuery& q) { return q.index->memory_bytes(); })
      .def(
          "lowest",
          [](const PyQuery& q, const py::handle& d) {
            Vectors v = vectors(d, "d");
            check_unit(v.v, "d");
            std::vector<Nearest> out(v.v.size());
            {
              py::gil_scoped_release nogil;
              q.index->lowest(v.v, out);
            }
            return nearest_to_dict(out, v.single);
          },
          py::arg("d"),
          "lowest(self: ContactQuery, d: numpy.typing.ArrayLike) -> dict[str, numpy.ndarray]\n\n"
          "The two lowest asperities for unit body-frame down directions d, shape (M, 3) or (3,): dict of index, key, "
          "runner_up, runner_up_key.")
      .def(
          "contact",
          [](const PyQuery& q, const py::handle& qs) {
            bool single = false;
            const std::vector<Rotation> rot = quaternions(qs, single);
            std::vector<Vec3> d(rot.size()), r(rot.size());
            std::vector<Nearest> nn(rot.size());
            std::vector<double> rxy(rot.size()), gap(rot.size());
            std::vector<std::uint8_t> core(rot.size());
            std::vector<std::uint32_t> index(rot.size());
            {
              py::gil_scoped_release nogil;
              for (std::size_t i = 0; i < rot.size(); ++i) d[i] = body_down(rot[i]);
              q.index->lowest(d, nn);
              const auto& b = q.sphere->body;
              for (std::size_t i = 0; i < rot.size(); ++i) {
                const Contact c = make_contact(nn[i], b.centres[nn[i].index], rot[i], b.params.radius, b.params.asperity_radius);
                r[i] = c.r, rxy[i] = c.r_xy, gap[i] = c.gap, core[i] = c.core, index[i] = c.index;
              }
            }
            py::dict out;
            out["index"] = to_numpy(std::move(index));
            out["r"] = vectors_to_numpy(r, false);
            out["r_xy"] = to_numpy(std::move(rxy));
            out["gap"] = to_numpy(std::move(gap));
            out["core"] = to_numpy_bool(core);
            return out;
          },
          py::arg("q"),
          "contact(self: ContactQuery, q: numpy.typing.ArrayLike) -> dict[str, numpy.ndarray]\n\n"
          "World-frame contacts of the body rotated by unit quaternions q = (w, x, y, z), shape (M, 4): dict of index, r "
          "(M, 3) [m], r_xy [m], gap [m], core.");
  m.def("backends", [] {
    std::vector<std::string> v;
    for (const Backend b : all_backends()) v.emplace_back(to_string(b));
    return v;
  }, "backends() -> list[str]\n\nThe contact query backends this build has (RoughSphere.query(backend)).");
  m.def(
      "body_down",
      [](const py::handle& qs) {
        bool single = false;
        const auto rot = quaternions(qs, single);
        std::vector<Vec3> d;
        for (const auto& r : rot) d.push_back(body_down(r));
        return vectors_to_numpy(d, single);
      },
      py::arg("q"),
      "body_down(q: numpy.typing.ArrayLike) -> numpy.ndarray\n\n"
      "The world's down direction in the body frame of bodies rotated by unit quaternions q = (w, x, y, z), shape (M, 4) "
      "or (4,).");
}

void bind_restitution(py::module_& m) {
  const PythonSignatures signatures;
  py::class_<Restitution, std::shared_ptr<Restitution>>(m, "Restitution", "A microscopic eps_n(v) model (core/restitution.hpp).")
      .def_property_readonly("name", &Restitution::name)
      .def(
          "__call__",
          [](std::shared_ptr<Restitution> self, const py::handle& v) {
            return elementwise(v, [&](double x) {
              if (!(x >= 0) || !std::isfinite(x)) throw std::invalid_argument("v = " + std::to_string(x) + ": speed must be finite and >= 0");
              return (*self)(x);
            }, "v");
          },
          py::arg("v"),
          "__call__(self: Restitution, v: float | numpy.typing.ArrayLike) -> float | numpy.ndarray\n\n"
          "eps_n at normal contact speeds v >= 0 [m/s] (a number or an array).");
  m.def(
      "pade14",
      [](double beta) -> std::shared_ptr<Restitution> {
        if (!(beta > 0) || !std::isfinite(beta)) value_error("beta = " + std::to_string(beta) + ": must be finite and > 0");
        return viscoelastic_pade14(beta);
      },
      py::arg("beta") = 0.0467, "pade14(beta: float = 0.0467) -> Restitution\n\nViscoelastic eps_n, Pade [1/4] of Eq. 9.");
  m.def(
      "constant",
      [](double e) -> std::shared_ptr<Restitution> {
        if (!(e >= 0 && e <= 1)) value_error("e = " + std::to_string(e) + ": must be in [0, 1]");
        return constant_restitution(e);
      },
      py::arg("e"), "constant(e: float) -> Restitution\n\neps_n = e at every speed, e in [0, 1].");
}

void bind_impulse(py::module_& m) {
  const PythonSignatures signatures;
  m.def(
      "solve_impact",
      [](double mass, const py::handle& inertia, const py::handle& V, const py::handle& Omega, const py::handle& r,
         const py::handle& n, const py::handle& eps_n, double eps_t) {
        if (!(mass > 0) || !std::isfinite(mass)) value_error("mass = " + std::to_string(mass) + ": must be finite and > 0");
        RigidBody body;
        body.mass = mass;
        if (py::isinstance<py::float_>(inertia) || py::isinstance<py::int_>(inertia)) {
          const double J = inertia.cast<double>();
          if (!(J > 0) || !std::isfinite(J)) value_error("inertia = " + show(inertia) + ": must be finite and > 0");
          body.inertia = J * Eigen::Matrix3d::Identity();
        } else {
          const Doubles a = doubles(inertia, "inertia", "a number or a 3x3 array");
          if (a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3) value_error("inertia: expected a number or a 3x3 array");
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) body.inertia(i, j) = a.at(i, j);
        }
        const auto model = restitution_model(eps_n);
        Vectors vv = vectors(V, "V"), vo = vectors(Omega, "Omega"), vr = vectors(r, "r"), vn = vectors(n, "n");
        std::size_t m = 1;
        for (const Vectors* x : {&vv, &vo, &vr, &vn})
          if (!x->single) {
            if (m != 1 && x->v.size() != m) value_error("V, Omega, r, n: arrays of different lengths (" + std::to_string(m) + " and " + std::to_string(x->v.size()) + ")");
            m = x->v.size();
          }
        const bool single = vv.single && vo.single && vr.single && vn.single;
        auto at = [](const Vectors& x, std::size_t i) -> const Vec3& { return x.single ? x.v[0] : x.v[i]; };
        std::vector<Vec3> P(m), Va(m), Oa(m);
        std::vector<double> eps(m), en(m), vnv(m);
        std::vector<std::uint8_t> impact(m);
        {
          py::gil_scoped_release nogil;
          const double nan = std::nan("");
          for (std::size_t i = 0; i < m; ++i) {
            ImpactState s;
            s.V = at(vv, i), s.Omega = at(vo, i), s.r = at(vr, i), s.n = at(vn, i);
            const auto res = solve_impact(body, s, *model, eps_t);
            impact[i] = res.has_value();
            if (res) {
              P[i] = res->P, Va[i] = res->V_after, Oa[i] = res->Omega_after, eps[i] = res->eps, en[i] = res->eps_n, vnv[i] = res->v_n;
            } else {
              P[i] = Va[i] = Oa[i] = Vec3::Constant(nan);
              eps[i] = en[i] = nan;
              vnv[i] = (s.V + s.Omega.cross(s.r)).dot(s.n);
            }
          }
        }
        py::dict out;
        out["P"] = vectors_to_numpy(P, single);
        out["V_after"] = vectors_to_numpy(Va, single);
        out["Omega_after"] = vectors_to_numpy(Oa, single);
        if (single) {
          out["eps"] = eps[0], out["eps_n"] = en[0], out["v_n"] = vnv[0], out["impact"] = impact[0] != 0;
        } else {
          out["eps"] = to_numpy(std::move(eps)), out["eps_n"] = to_numpy(std::move(en)), out["v_n"] = to_numpy(std::move(vnv));
          out["impact"] = to_numpy_bool(impact);
        }
        return out;
      },
      py::arg("mass"), py::arg("inertia"), py::arg("V"), py::arg("Omega"), py::arg("r"), py::arg("n") = std::vector<double>{0, 0, 1},
      py::arg("eps_n") = 1.0, py::arg("eps_t") = 1.0,
      "solve_impact(mass: float, inertia: float | numpy.typing.ArrayLike, V: numpy.typing.ArrayLike, "
      "Omega: numpy.typing.ArrayLike, r: numpy.typing.ArrayLike, n: numpy.typing.ArrayLike = [0.0, 0.0, 1.0], "
      "eps_n: float | Restitution = 1.0, eps_t: float = 1.0) -> dict[str, Any]\n\n"
      R"doc(Impulse solve of Eq. 7 (core/impact.hpp) over arrays: V, Omega, r, n of shape (M, 3) or (3,)
(broadcast); inertia a number (J = inertia x identity) or a 3x3 world-frame tensor; eps_n a number or
a model (asperity.pade14()). Returns a dict of P, V_after, Omega_after, eps, eps_n, v_n, impact; rows
without an impact (v_n >= 0) are NaN with impact False.)doc");
}

void bind_laws(py::module_& m) {
  std::optional<PythonSignatures> signatures(std::in_place);  // pdf, cdf take a number or an array
  py::class_<Law>(m, "Law", "A one-dimensional law with pdf and cdf (laws/theory.hpp).")
      .def_readonly("name", &Law::name)
      .def_readonly("description", &Law::description)
      .def_readonly("mean", &Law::mean)
      .def("pdf", [](const Law& l, const py::handle& x) { return elementwise(x, [&](double t) { return l.pdf(t); }); }, py::arg("x"),
           "pdf(self: Law, x: float | numpy.typing.ArrayLike) -> float | numpy.ndarray\n\nThe probability density at x.")
      .def("cdf", [](const Law& l, const py::handle& x) { return elementwise(x, [&](double t) { return l.cdf(t); }); }, py::arg("x"),
           "cdf(self: Law, x: float | numpy.typing.ArrayLike) -> float | numpy.ndarray\n\nThe cumulative distribution at x.")
      .def("__repr__", [](const Law& l) { return "<asperity.Law " + l.name + ": " + l.description + ">"; });
  signatures.reset();
  auto check_nr = [](std::uint64_t n, double R) {
    check_asperity_count(n, "asperities");
    if (!(R > 0) || !std::isfinite(R)) value_error("radius = " + std::to_string(R) + ": must be finite and > 0");
  };
  m.def("eq14_rxy", [=](std::uint64_t n, double R) { check_nr(n, R); return eq14_rxy(n, R); }, py::arg("asperities"), py::arg("radius"),
        "Eq. 14: law of r_xy [m] (flat cap, Poisson points; Rayleigh).");
  m.def("exact_sphere_rxy", [=](std::uint64_t n, double R) { check_nr(n, R); return exact_sphere_rxy(n, R); }, py::arg("asperities"),
        py::arg("radius"), "Exact finite-N law of r_xy [m] on the sphere.");
  m.def("eq18_rx", [=](std::uint64_t n, double R) { check_nr(n, R); return eq18_rx(n, R); }, py::arg("asperities"), py::arg("radius"),
        "Eq. 18: law of r_x [m] (Normal).");
  m.def("exact_sphere_rx", [=](std::uint64_t n, double R) { check_nr(n, R); return exact_sphere_rx(n, R); }, py::arg("asperities"),
        py::arg("radius"), "Exact finite-N law of r_x [m] on the sphere.");
  m.def(
      "core_contact_probability",
      [=](std::uint64_t n, double R, double a) {
        check_nr(n, R);
        if (!(a > 0) || !(a < R)) value_error("asperity_radius = " + std::to_string(a) + ": must be > 0 and < radius");
        return core_contact_probability(n, R, a);
      },
      py::arg("asperities"), py::arg("radius"), py::arg("asperity_radius"),
      "The probability that a drop's contact is the core sphere rather than an asperity (N asperities of radius "
      "asperity_radius [m] on a sphere of radius [m]).");
#define ASPERITY_IMPACT_LAW(fn, doc)                                                                                        \
  m.def(                                                                                                                    \
      #fn,                                                                                                                  \
      [](std::uint64_t n, double R, double a, double speed, double omega_x, double omega_y, double beta, bool core) {       \
        const ImpactScene s = impact_scene(n, R, a, speed, omega_x, omega_y, beta, core);                                   \
        validate(s);                                                                                                        \
        return fn(s);                                                                                                       \
      },                                                                                                                    \
      py::arg("asperities") = 100000, py::arg("radius") = 3e-3, py::arg("asperity_radius") = 6.5e-7, py::arg("speed") = 1.3, \
      py::arg("omega_x") = 0.2, py::arg("omega_y") = 0.0, py::arg("beta") = 0.0467, py::arg("core_contacts") = false, doc)
  ASPERITY_IMPACT_LAW(eq28_printed, "Eq. 28 as printed: law of eps (normalised; see the description).");
  ASPERITY_IMPACT_LAW(eq28_corrected, "Eq. 28 corrected: law of eps (docs/sec4-derivations.md).");
  ASPERITY_IMPACT_LAW(eq28_paper_route, "The paper's route to Eq. 28 carried out correctly: law of eps.");
  ASPERITY_IMPACT_LAW(eq33_printed, "Eq. 33 as printed: law of Omega'_x [rad/s].");
  ASPERITY_IMPACT_LAW(eq33_corrected, "Eq. 33 corrected: law of Omega'_x [rad/s].");
#undef ASPERITY_IMPACT_LAW
}

void bind_tables(py::module_& m) {
  const PythonSignatures signatures;
  m.def(
      "cor_table",
      [](const py::handle& scene, const py::object& speeds, std::size_t probabilities, const py::object& drops,
         const py::object& path, const py::object& progress, const py::object& spins, std::size_t omega_bands) {
        check_callable(progress);
        CorTableSpec spec = cor_table_spec(to_scene(scene));
        try {
          if (!speeds.is_none()) spec.speeds = speeds.cast<std::vector<double>>();
        } catch (const py::cast_error&) {
          type_error("speeds: expected a sequence of numbers [m/s], got " + show(speeds));
        }
        try {
          if (!spins.is_none()) spec.spins = spins.cast<std::vector<double>>();
        } catch (const py::cast_error&) {
          type_error("spins: expected a sequence of numbers [rad/s], got " + show(spins));
        }
        spec.omega_bands = omega_bands;
        spec.probabilities = probabilities;
        if (!drops.is_none()) {
          if (py::isinstance<py::bool_>(drops) || py::isinstance<py::float_>(drops) || !py::hasattr(drops, "__index__"))
            type_error("drops: expected an integer, got " + show(drops));
          const py::int_ d = index_of(drops);  // numpy integers too
          if (d < py::int_(0) || d > py::int_(std::uint64_t(-1))) value_error("drops = " + show(drops) + ": expected a positive integer");
          spec.drops = d.cast<std::uint64_t>();
        }
        validate(spec);
        check_bytes(cor_table_bytes(spec),
                    std::to_string(spec.drops) + " drops per speed, " + std::to_string(spec.probabilities) + " probabilities x " +
                        std::to_string(spec.speeds.size()) + " speeds",
                    "drops, probabilities, speeds, spins or omega_bands");
        const std::string file = path.is_none() ? std::string() : path_bytes(path, "path");
        if (!file.empty() && std::filesystem::path(file).extension() != ".csv")
          value_error("path = '" + file + "': must end in .csv (its header is written beside it as .json)");
        const Progress p = python_progress(progress);
        CorTable t;
        std::vector<std::filesystem::path> files;
        {
          py::gil_scoped_release nogil;
          t = make_cor_table(spec, p);
          if (!file.empty()) files = write_cor_table(file, t);
        }
        std::vector<double> q;
        for (const auto& row : t.rows) q.insert(q.end(), row.quantiles.begin(), row.quantiles.end());
        // The .json header's keys, once each; its grids as arrays (speeds_m_s, probabilities, spins_rad_s).
        py::dict out = py::module_::import("json").attr("loads")(cor_table_json(t));
        out["speeds_m_s"] = to_numpy(std::vector<double>(spec.speeds));
        out["probabilities"] = to_numpy(std::vector<double>(t.probabilities));
        if (out.contains("spins_rad_s")) out["spins_rad_s"] = to_numpy(out["spins_rad_s"].cast<std::vector<double>>());
        const auto P = static_cast<py::ssize_t>(t.probabilities.size()), S = static_cast<py::ssize_t>(spec.speeds.size());
        if (t.format() == 1) {
          out["quantiles"] = to_numpy(std::move(q)).reshape({S, P});
        } else {  // (spins, speeds, p) and, with omega_bands, (spins, speeds, bands, p)
          const auto K = static_cast<py::ssize_t>(t.rows.size()) / S;
          out["quantiles"] = to_numpy(std::move(q)).reshape({K, S, P});
          std::vector<double> w;
          for (const auto& row : t.rows)
            for (const auto& band : row.omega_x_band_quantiles) w.insert(w.end(), band.begin(), band.end());
          out["omega_band_quantiles"] = to_numpy(std::move(w)).reshape({K, S, static_cast<py::ssize_t>(spec.omega_bands), P});
        }
        py::list written;
        for (const auto& f : files) written.append(f.string());
        out["files"] = written;
        return out;
      },
      py::arg("scene") = "fig4", py::arg("speeds") = py::none(), py::arg("probabilities") = 201, py::arg("drops") = py::none(),
      py::arg("path") = py::none(), py::arg("progress") = py::none(), py::arg("spins") = py::none(),
      py::arg("omega_bands") = 0,
      (std::string("cor_table(scene: ") + kSceneType +
       " = 'fig4', speeds: Sequence[float] | None = None, probabilities: int = 201, drops: int | None = None, "
       "path: str | os.PathLike[str] | None = None, progress: Callable[[int, int], Any] | None = None, "
       "spins: Sequence[float] | None = None, omega_bands: int = 0) -> dict[str, Any]\n\n" +
       R"doc(A restitution table for DEM codes (app/cor_table.hpp; docs/dem-tables.md).

The sphere, material, spin and seed come from `scene` (a sphere impact scene); speeds [m/s]
default to 9 points from u/10 to 10 u around its impact speed u; drops per speed (sampled from the exact law of the lowest asperity)
default to 1e5. Returns the table's .json header as a dict, its grids speeds_m_s and
probabilities as arrays, plus quantiles (speeds x probabilities); with path (ending in .csv),
writes the CSV and the .json next to it (files lists them; asperity.read_cor_table reads them back). spins [rad/s] (incoming
Omega = (spin, 0, 0)) and/or omega_bands (Omega'_x quantiles per eps band, for joint draws) make a
format-2 table: quantiles then has shape (spins, speeds, p) and omega_band_quantiles
(spins, speeds, bands, p).)doc")
          .c_str());
}

}  // namespace

PYBIND11_MODULE(_asperity, m) {
  // A run refused by the memory estimate is MemoryError with the CLI's message (resources.hpp);
  // std::bad_alloc is MemoryError and std::invalid_argument ValueError by pybind11's own rules.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const MemoryRefused& e) {
      PyErr_SetString(PyExc_MemoryError, e.what());
    }
  });
  m.doc() = "asperity: explicit-geometry contacts and restitution of rough particles (C++ library bindings)";
  m.attr("__version__") = ASPERITY_VERSION;

  bind_scenes_and_runs(m);
  bind_spheres(m);
  bind_queries(m);
  bind_restitution(m);
  bind_impulse(m);
  bind_laws(m);
  bind_tables(m);
}

// The extension module morphomap._core: exception registration and the feature bindings.
// Arguments arrive as float64 C-contiguous arrays (the Python layer sees to that), so the C++
// side takes them as zero-copy Eigen views; kernels run with the GIL released.
#include <pybind11/pybind11.h>

#include <morphomap/build_info.hpp>
#include <morphomap/errors.hpp>

#include "interrupt_guard.hpp"

#include <tbb/global_control.h>

#include <string>

namespace py = pybind11;

void bind_curves(py::module_& m);
void bind_mapping(py::module_& m);
void bind_transform(py::module_& m);
void bind_quality(py::module_& m);
void bind_surfaces(py::module_& m);
void bind_diffusion3d(py::module_& m);
void bind_field_at(py::module_& m);
void bind_growth(py::module_& m);
void bind_extend(py::module_& m);

PYBIND11_MODULE(_core, m) {
  m.doc() = "morphomap C++ core (use the morphomap package, not this module)";
  py::register_exception<morphomap::InvalidInput>(m, "InvalidInput", PyExc_ValueError);
  py::register_exception<morphomap::GeometryError>(m, "GeometryError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr thrown) {
    try {
      if (thrown) std::rethrow_exception(thrown);
    } catch (const morphomap::Interrupted&) {
      PyErr_SetNone(PyExc_KeyboardInterrupt);
    }
  });
  record_main_thread();

  m.def("build_info", [] {
    const auto info = morphomap::build_info();
    py::dict d;
    d["version"] = info.version;
    d["cgal"] = info.cgal;
    d["embree"] = info.embree;
    d["eigen"] = info.eigen;
    d["tbb"] = info.tbb;
    d["threads"] = info.threads;
    return d;
  });
  // For processes that share the cores with others (map_batch's workers): TBB, and Embree, which
  // runs on it, use at most `threads` threads in this process from now on.
  m.def(
      "limit_threads",
      [](int threads) {
        if (threads < 1) throw morphomap::InvalidInput("threads: must be at least 1, got " + std::to_string(threads));
        // Kept to the end of the process (not destroyed at exit, after TBB may have gone).
        static tbb::global_control* limit = nullptr;
        auto* next =
            new tbb::global_control(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
        delete limit;
        limit = next;
      },
      py::arg("threads"));
  m.def("active_threads",
        [] { return tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism); });
  bind_curves(m);
  bind_mapping(m);
  bind_transform(m);
  bind_quality(m);
  bind_surfaces(m);
  bind_diffusion3d(m);
  bind_field_at(m);
  bind_growth(m);
  bind_extend(m);
}

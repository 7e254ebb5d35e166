// The extension module morphomap._core: exception registration and the feature bindings.
// Arguments arrive as float64 C-contiguous arrays (the Python layer sees to that), so the C++
// side takes them as zero-copy Eigen views; kernels run with the GIL released.
#include <pybind11/pybind11.h>

#include <morphomap/build_info.hpp>
#include <morphomap/errors.hpp>

#include "interrupt_guard.hpp"

namespace py = pybind11;

void bind_curves(py::module_& m);
void bind_mapping(py::module_& m);
void bind_transform(py::module_& m);
void bind_quality(py::module_& m);
void bind_surfaces(py::module_& m);
void bind_diffusion3d(py::module_& m);
void bind_field_at(py::module_& m);
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
  bind_curves(m);
  bind_mapping(m);
  bind_transform(m);
  bind_quality(m);
  bind_surfaces(m);
  bind_diffusion3d(m);
  bind_field_at(m);
  bind_extend(m);
}

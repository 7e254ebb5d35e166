// Bindings of 3D diffusion mapping: the Laplace problem in the shell between two closed surfaces.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <morphomap/laplace3d.hpp>

#include "interrupt_guard.hpp"
#include "stage_callback.hpp"

#include <algorithm>

namespace py = pybind11;
using namespace morphomap;

void bind_diffusion3d(py::module_& m) {
  m.def(
      "solve_diffusion_3d",
      [](const Points3Ref& source_vertices, const FacesRef& source_faces, const Points3Ref& target_vertices,
         const FacesRef& target_faces, double mesh_size, bool keep_streamlines, bool repeatable,
         const py::object& on_stage) {
        ShellDiffusionOptions options;
        options.mesh_size = mesh_size;
        options.repeatable = repeatable;
        options.keep_streamlines = keep_streamlines;
        options.on_stage = stage_callback(on_stage);
        ShellDiffusionSolution solution;
        InterruptGuard interruptible;
        {
          py::gil_scoped_release release;
          solution = solve_diffusion_3d(source_vertices, source_faces, target_vertices, target_faces, options);
        }
        py::list streamlines;
        for (Points3& line : solution.streamlines) streamlines.append(py::cast(std::move(line)));
        py::dict seconds;
        seconds["mesh"] = solution.seconds.mesh;
        seconds["solve"] = solution.seconds.solve;
        seconds["trace"] = solution.seconds.trace;
        py::array_t<bool> touching(static_cast<py::ssize_t>(solution.touching.size()));
        std::copy(solution.touching.begin(), solution.touching.end(), touching.mutable_data());
        py::dict result;
        result["vertices"] = std::move(solution.vertices);
        result["tetrahedra"] = std::move(solution.tetrahedra);
        result["potential"] = std::move(solution.potential);
        result["ends"] = std::move(solution.ends);
        result["touching"] = touching;
        result["streamlines"] = streamlines;
        result["seconds"] = seconds;
        return result;
      },
      py::arg("source_vertices"), py::arg("source_faces"), py::arg("target_vertices"), py::arg("target_faces"),
      py::arg("mesh_size"), py::arg("keep_streamlines"), py::arg("repeatable"), py::arg("on_stage") = py::none());
}

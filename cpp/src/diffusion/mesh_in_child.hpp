#pragma once
// CGAL's Mesh_3 (5.5) can crash on valid input: on frames contoured from masks its refinement
// segfaults in the triangulation's insert_in_hole (pairs of the 3D fuzz suite, bench/README.md,
// "Contact patches cut out"; the same pair meshes at other element sizes). A crash there must not
// take the caller's process down, so the mesh is made in a forked child and sent back through a
// pipe; a child that dies becomes a GeometryError, and the caller may try again with other
// settings. The child runs the mesher only (no Python, no Embree), allocating through glibc's
// malloc, which its fork handlers leave usable however many threads the parent has. TBB's worker
// threads do not survive a fork: a child that is to run TBB work (the parallel mesher) gets its own
// only if this process's were stopped before the fork; otherwise its TBB work runs on its one
// thread.
#include "diffusion/shell_mesh.hpp"

#include <morphomap/errors.hpp>

#include <functional>

namespace morphomap::detail {

// The child died (a signal): the caller may retry with other settings.
class MesherCrashed : public GeometryError {
 public:
  using GeometryError::GeometryError;
};

// Runs `make` in a child process (where fork exists; else in this one) and returns its mesh. Its
// InvalidInput and GeometryError come back as such; a child killed by a signal gives a
// MesherCrashed naming `what` and the signal. Polls check_interrupt while it waits (the child is
// then killed).
ShellMesh mesh_in_child(const std::function<ShellMesh()>& make, const char* what);

// The same for a `make` that may run TBB work: this process's TBB workers are stopped first
// (tbb::finalize; they start again at its next TBB call), so that the child can start its own.
// tbb::finalize refuses while another thread is in TBB: `make` is then told to use one thread.
// Another thread may still enter TBB between the finalize and the fork and hold a lock of TBB's
// (or its allocator's) that the child then waits on forever: a threaded child whose CPU time has
// not moved for stall_seconds (where /proc tells) is killed and the mesh made again by a
// child on one thread.
ShellMesh mesh_in_child_threaded(const std::function<ShellMesh(bool threads)>& make, const char* what,
                                 double stall_seconds = 10.0);

}  // namespace morphomap::detail

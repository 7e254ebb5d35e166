// The child-process guard around Mesh_3 (an internal of the core, tested through its header): a
// mesh comes back intact, the core's exceptions come back as themselves, and a crash in the child
// becomes MesherCrashed while this process carries on.
#include "diffusion/mesh_in_child.hpp"

#include <morphomap/errors.hpp>

#include "check.hpp"

#include <pthread.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <string>
#include <thread>
#include <vector>

using morphomap::detail::mesh_in_child;
using morphomap::detail::ShellMesh;

namespace {

ShellMesh one_tetrahedron() {
  ShellMesh mesh;
  mesh.vertices.resize(4, 3);
  mesh.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1.5;
  mesh.tetrahedra.resize(1, 4);
  mesh.tetrahedra << 0, 1, 2, 3;
  mesh.neighbours = decltype(mesh.neighbours)::Constant(1, 4, -1);
  mesh.patches.resize(1, 4);
  mesh.patches << 1, 2, -1, 0;
  return mesh;
}

void round_trip() {
  const ShellMesh sent = one_tetrahedron();
  const ShellMesh got = mesh_in_child([&] { return sent; }, "test");
  CHECK(got.vertices == sent.vertices);
  CHECK(got.tetrahedra == sent.tetrahedra);
  CHECK(got.neighbours == sent.neighbours);
  CHECK(got.patches == sent.patches);
}

void exceptions_come_back() {
  try {
    mesh_in_child([]() -> ShellMesh { throw morphomap::InvalidInput("s2: made up"); }, "test");
    CHECK(false);
  } catch (const morphomap::InvalidInput& e) {
    CHECK(std::string(e.what()) == "s2: made up");
  }
  try {
    mesh_in_child([]() -> ShellMesh { throw morphomap::GeometryError("no tetrahedra"); }, "test");
    CHECK(false);
  } catch (const morphomap::detail::MesherCrashed&) {
    CHECK(false);  // an ordinary failure is no crash
  } catch (const morphomap::GeometryError& e) {
    CHECK(std::string(e.what()) == "no tetrahedra");
  }
}

void a_crash_is_an_error() {
  for (const int sig : {SIGSEGV, SIGFPE, SIGABRT}) {
    try {
      mesh_in_child(
          [sig]() -> ShellMesh {
            std::raise(sig);
            return {};
          },
          "meshing the test region");
      CHECK(false);
    } catch (const morphomap::detail::MesherCrashed& e) {
      const std::string message = e.what();
      CHECK(message.find("meshing the test region crashed") == 0);
      CHECK(message.find("signal " + std::to_string(sig)) != std::string::npos);
    }
  }
  round_trip();  // and the guard still works afterwards
}

// Threads that mesh at once fork one at a time: a library's fork handlers (OpenBLAS's joins its
// threads) may not run twice at once. A prepare handler of our own sees whether two forks overlap;
// its pause makes an overlap near certain if the guard lets forks run together.
std::atomic<int> forks_in_prepare{0};
std::atomic<bool> forks_overlapped{false};

void forks_are_serialized() {
  ::pthread_atfork(
      [] {
        if (forks_in_prepare.fetch_add(1) > 0) forks_overlapped = true;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      },
      [] { forks_in_prepare.fetch_sub(1); }, nullptr);
  const ShellMesh sent = one_tetrahedron();
  std::vector<int> intact(4, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (int k = 0; k < 5; ++k)
        intact[t] += mesh_in_child([&] { return sent; }, "test").tetrahedra == sent.tetrahedra;
    });
  }
  for (auto& thread : threads) thread.join();
  CHECK(!forks_overlapped);
  for (const int count : intact) CHECK(count == 5);
}

}  // namespace

int main() {
  round_trip();
  exceptions_come_back();
  a_crash_is_an_error();
  forks_are_serialized();
  TEST_MAIN_END();
}

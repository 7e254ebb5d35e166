// The child-process guard around Mesh_3 (an internal of the core, tested through its header): a
// mesh comes back intact, the core's exceptions come back as themselves, and a crash in the child
// becomes MesherCrashed while this process carries on. A threaded child gets TBB workers of its
// own after this process has used TBB, one thread while another thread is in TBB, and a child
// that stops using the CPU is replaced by one on one thread. A child does not outlive a parent
// killed outright.
#include "diffusion/mesh_in_child.hpp"

#include <morphomap/errors.hpp>

#include "check.hpp"

#include <oneapi/tbb/parallel_for.h>
#include <pthread.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <fstream>
#include <iterator>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

using morphomap::detail::mesh_in_child;
using morphomap::detail::mesh_in_child_threaded;
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

// How many threads a TBB loop of about half a second's work ran on.
int tbb_threads() {
  std::set<std::thread::id> ids;
  std::mutex guard;
  oneapi::tbb::parallel_for(0, 400, [&](int) {
    volatile double sum = 0.0;
    for (int k = 0; k < 300000; ++k) sum = sum + k;
    const std::lock_guard<std::mutex> lock(guard);
    ids.insert(std::this_thread::get_id());
  });
  return static_cast<int>(ids.size());
}

// The child reports its thread count as the mesh's one vertex.
ShellMesh threads_seen(bool threads) {
  ShellMesh mesh = one_tetrahedron();
  mesh.vertices(0, 0) = threads;
  mesh.vertices(0, 1) = tbb_threads();
  return mesh;
}

void a_threaded_child_has_workers() {
  const int here = tbb_threads();  // this process's workers exist now
  if (std::thread::hardware_concurrency() < 2 || here < 2) return;
  const ShellMesh got = mesh_in_child_threaded(threads_seen, "test");
  CHECK(got.vertices(0, 0) == 1.0);
  CHECK(got.vertices(0, 1) >= 2.0);
  CHECK(tbb_threads() >= 2);  // and this process has its workers back
}

void another_thread_in_tbb_means_one_thread() {
  // The other thread stays inside one TBB loop until the child has answered, so that
  // tbb::finalize must refuse and the child must be told to use one thread.
  std::atomic<bool> stop{false}, inside{false};
  std::thread busy([&] {
    oneapi::tbb::parallel_for(0, 1, [&](int) {
      inside = true;
      while (!stop) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    });
  });
  while (!inside) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const ShellMesh got = mesh_in_child_threaded(threads_seen, "test");
  stop = true;
  busy.join();
  CHECK(got.vertices(0, 0) == 0.0);  // told to use one thread
  CHECK(got.vertices(0, 1) == 1.0);  // and its TBB had no workers of its own
}

void a_stalled_child_is_replaced() {
  const auto start = std::chrono::steady_clock::now();
  const ShellMesh got = mesh_in_child_threaded(
      [](bool threads) {
        if (threads) ::pause();  // waits for a signal: no CPU time, as a child stuck on a lock
        return one_tetrahedron();
      },
      "test", 0.5);
  CHECK(got.tetrahedra == one_tetrahedron().tetrahedra);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK(seconds > 0.5 && seconds < 5.0);
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
      for (int k = 0; k < 5; ++k) {  // the threaded guard stops TBB and forks under the same lock
        const ShellMesh got = k % 2 ? mesh_in_child([&] { return sent; }, "test")
                                    : mesh_in_child_threaded([&](bool) { return sent; }, "test");
        intact[t] += got.tetrahedra == sent.tetrahedra;
      }
    });
  }
  for (auto& thread : threads) thread.join();
  CHECK(!forks_overlapped);
  for (const int count : intact) CHECK(count == 5);
}

#if defined(__linux__)  // (the guard asks Linux to end the child; elsewhere it is not promised)
// Whether process `pid` has ended (gone, or a zombie nobody has reaped yet).
bool ended(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  if (!stat) return true;
  std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
  const std::size_t close = text.rfind(')');
  return close == std::string::npos || close + 2 >= text.size() || text[close + 2] == 'Z' || text[close + 2] == 'X';
}

// A process meshing in a child is killed outright (SIGKILL, as a harness's timeout does): its child
// must not mesh on alone. (It used to: orphaned mesher children of killed fuzz workers kept both
// cores busy for minutes.)
void a_child_dies_with_its_parent() {
  int fds[2];
  CHECK(::pipe(fds) == 0);
  const pid_t middle = ::fork();
  if (middle == 0) {
    ::close(fds[0]);
    try {
      mesh_in_child(
          [&] {
            const pid_t me = ::getpid();
            CHECK(::write(fds[1], &me, sizeof me) == static_cast<ssize_t>(sizeof me));
            for (;;) ::pause();  // a mesher that never finishes
            return one_tetrahedron();
          },
          "test");
    } catch (...) {
    }
    ::_exit(0);
  }
  ::close(fds[1]);
  pid_t meshing = 0;
  CHECK(::read(fds[0], &meshing, sizeof meshing) == static_cast<ssize_t>(sizeof meshing));
  ::close(fds[0]);
  ::kill(middle, SIGKILL);
  ::waitpid(middle, nullptr, 0);
  bool gone = false;
  for (int k = 0; k < 250 && !gone; ++k) {
    gone = ended(meshing);
    if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  CHECK(meshing > 0 && gone);
  if (meshing > 0 && !gone) ::kill(meshing, SIGKILL);  // (never kill(0): that is our own group)
}
#endif

}  // namespace

int main() {
  round_trip();
  exceptions_come_back();
  a_crash_is_an_error();
  a_threaded_child_has_workers();
  another_thread_in_tbb_means_one_thread();
  a_stalled_child_is_replaced();
#if defined(__linux__)
  a_child_dies_with_its_parent();
#endif
  forks_are_serialized();
  TEST_MAIN_END();
}

// See mesh_in_child.hpp. The protocol on the pipe: one status byte (0: a mesh follows, 1:
// InvalidInput, 2: GeometryError, 3: Interrupted), then either the message (its length, then its
// bytes) or the mesh (vertex and tetrahedron counts, then the four arrays' raw bytes).
#include "diffusion/mesh_in_child.hpp"

#include "common/interrupt_check.hpp"

#include <morphomap/errors.hpp>

#include <oneapi/tbb/global_control.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <new>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#if defined(__unix__) || defined(__APPLE__)
#include <poll.h>
#include <signal.h>
#if defined(__linux__)
#include <sys/prctl.h>
#endif
#include <sys/wait.h>
#include <unistd.h>
#define MORPHOMAP_HAVE_FORK 1
#endif

namespace morphomap::detail {

#ifndef MORPHOMAP_HAVE_FORK

ShellMesh mesh_in_child(const std::function<ShellMesh()>& make, const char*) { return make(); }

ShellMesh mesh_in_child_threaded(const std::function<ShellMesh(bool threads)>& make, const char*, double) {
  return make(true);
}

#else

namespace {

enum Status : char { mesh_follows = 0, invalid_input = 1, geometry_error = 2, interrupted = 3 };

// Child side: everything goes out in one buffer (a write may be partial).
void write_all(int fd, const std::vector<char>& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

template <class T>
void put(std::vector<char>& out, const T* data, std::size_t count) {
  const char* bytes = reinterpret_cast<const char*>(data);
  out.insert(out.end(), bytes, bytes + count * sizeof(T));
}

std::vector<char> encode(const ShellMesh& mesh) {
  std::vector<char> out(1, mesh_follows);
  const std::int64_t counts[2] = {mesh.vertices.rows(), mesh.tetrahedra.rows()};
  put(out, counts, 2);
  put(out, mesh.vertices.data(), static_cast<std::size_t>(mesh.vertices.size()));
  put(out, mesh.tetrahedra.data(), static_cast<std::size_t>(mesh.tetrahedra.size()));
  put(out, mesh.neighbours.data(), static_cast<std::size_t>(mesh.neighbours.size()));
  put(out, mesh.patches.data(), static_cast<std::size_t>(mesh.patches.size()));
  return out;
}

std::vector<char> encode(Status status, const std::string& message) {
  std::vector<char> out(1, status);
  const std::int64_t length = static_cast<std::int64_t>(message.size());
  put(out, &length, 1);
  put(out, message.data(), message.size());
  return out;
}

[[noreturn]] void run_child(int fd, pid_t parent, const std::function<ShellMesh()>& make) {
  // The parent's handlers (Python's faulthandler, say) would report the crash as the parent's
  // own; the parent reports it. Ctrl-C reaches the parent, which ends the child.
  for (const int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) ::signal(sig, SIG_DFL);
  ::signal(SIGINT, SIG_IGN);
#if defined(__linux__)
  // A parent killed outright (SIGKILL, a test harness's timeout) cannot end its child: the child
  // would mesh on alone, for minutes, on a core nobody waits for. The kernel ends it instead (the
  // forking thread waits for the child, so it outlives it unless the process dies). A parent that
  // died before the request shows as a new parent process id.
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(1);
#else
  (void)parent;
#endif
  std::vector<char> reply;
  try {
    reply = encode(make());
  } catch (const InvalidInput& e) {
    reply = encode(invalid_input, e.what());
  } catch (const GeometryError& e) {
    reply = encode(geometry_error, e.what());
  } catch (const Interrupted& e) {
    reply = encode(interrupted, e.what());
  } catch (const std::exception& e) {
    reply = encode(geometry_error, e.what());
  } catch (...) {
    reply = encode(geometry_error, "unknown failure");
  }
  write_all(fd, reply);
  ::close(fd);
  ::_exit(0);  // no destructors, atexit handlers or leak checks of the parent's state
}

class Reader {
 public:
  explicit Reader(const std::vector<char>& bytes) : bytes_(bytes) {}
  template <class T>
  void get(T* data, std::size_t count) {
    const std::size_t size = count * sizeof(T);
    if (at_ + size > bytes_.size()) throw GeometryError("meshing: the child process sent a truncated mesh");
    std::memcpy(reinterpret_cast<char*>(data), bytes_.data() + at_, size);
    at_ += size;
  }
  bool done() const { return at_ == bytes_.size(); }

 private:
  const std::vector<char>& bytes_;
  std::size_t at_ = 0;
};

ShellMesh decode(const std::vector<char>& bytes) {
  Reader in(bytes);
  Status status;
  in.get(reinterpret_cast<char*>(&status), 1);
  if (status != mesh_follows) {
    std::int64_t length = 0;
    in.get(&length, 1);
    if (length < 0 || static_cast<std::size_t>(length) > bytes.size()) {
      throw GeometryError("meshing: the child process sent a garbled message");
    }
    std::string message(static_cast<std::size_t>(length), '\0');
    in.get(message.data(), message.size());
    if (status == invalid_input) throw InvalidInput(message);
    if (status == interrupted) throw Interrupted();
    throw GeometryError(message);
  }
  std::int64_t counts[2] = {0, 0};
  in.get(counts, 2);
  const std::int64_t limit = static_cast<std::int64_t>(bytes.size());
  if (counts[0] < 0 || counts[1] < 0 || counts[0] > limit || counts[1] > limit) {
    throw GeometryError("meshing: the child process sent a garbled mesh");
  }
  ShellMesh mesh;
  mesh.vertices.resize(counts[0], 3);
  mesh.tetrahedra.resize(counts[1], 4);
  mesh.neighbours.resize(counts[1], 4);
  mesh.patches.resize(counts[1], 4);
  in.get(mesh.vertices.data(), static_cast<std::size_t>(mesh.vertices.size()));
  in.get(mesh.tetrahedra.data(), static_cast<std::size_t>(mesh.tetrahedra.size()));
  in.get(mesh.neighbours.data(), static_cast<std::size_t>(mesh.neighbours.size()));
  in.get(mesh.patches.data(), static_cast<std::size_t>(mesh.patches.size()));
  if (!in.done()) throw GeometryError("meshing: the child process sent more than a mesh");
  return mesh;
}

// Kills and reaps the child when the parent leaves early (an interrupt, a failed read).
struct Child {
  pid_t pid;
  bool reaped = false;
  ~Child() {
    if (reaped) return;
    ::kill(pid, SIGKILL);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  }
};

// CPU seconds the process has used (user and system), or -1 where /proc cannot tell.
double cpu_seconds(pid_t pid) {
  std::ifstream file("/proc/" + std::to_string(pid) + "/stat");
  std::string stat;
  if (!std::getline(file, stat)) return -1.0;
  // The command name (field 2) is in parentheses and may hold spaces: count from the last one.
  std::istringstream fields(stat.substr(stat.rfind(')') + 1));
  std::string field;
  long long ticks = 0;
  for (int k = 3; k <= 15 && fields >> field; ++k) {
    if (k >= 14) ticks += std::atoll(field.c_str());  // utime, stime
  }
  return static_cast<double>(ticks) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

// fork(), one thread at a time in this process. fork() runs every library's prepare handler in the
// forking thread, and some are not safe to run twice at once: OpenBLAS's (loaded with SciPy) joins
// its worker threads, and two concurrent forks joined the same thread, so one waited forever
// (three Python threads meshing at once hung in about one run in two). With stop_tbb, this
// process's TBB workers are stopped first, so that the child can start its own; tbb_stopped says
// whether they were (tbb::finalize refuses while another thread is in TBB).
pid_t fork_one_at_a_time(bool stop_tbb, bool& tbb_stopped) {
  static std::mutex forking;
  const std::lock_guard<std::mutex> lock(forking);
  tbb_stopped = false;
  if (stop_tbb) {
    oneapi::tbb::task_scheduler_handle workers{oneapi::tbb::attach{}};
    tbb_stopped = oneapi::tbb::finalize(workers, std::nothrow);
  }
  return ::fork();
}

// want_threads: `make` may run TBB work (see mesh_in_child_threaded). No mesh: a threaded child
// stopped using the CPU for stall_seconds and was killed.
std::optional<ShellMesh> fork_and_mesh(const std::function<ShellMesh(bool threads)>& make, const char* what,
                                       bool want_threads, double stall_seconds) {
  int fds[2];
  if (::pipe(fds) != 0) return make(want_threads);  // no pipe to spare: mesh here
  bool threads = false;
  const pid_t parent = ::getpid();
  const pid_t pid = fork_one_at_a_time(want_threads, threads);
  if (pid < 0) {  // no process to spare: mesh here, where TBB starts its workers again
    ::close(fds[0]);
    ::close(fds[1]);
    return make(want_threads);
  }
  if (pid == 0) {
    ::close(fds[0]);
    run_child(fds[1], parent, [&] { return make(threads); });
  }
  ::close(fds[1]);
  Child child{pid};
  std::vector<char> bytes;
  char buffer[1 << 16];
  double cpu = threads ? cpu_seconds(pid) : -1.0;
  auto cpu_moved = std::chrono::steady_clock::now();
  for (;;) {
    pollfd ready{fds[0], POLLIN, 0};
    const int polled = ::poll(&ready, 1, 100);
    if (polled < 0 && errno != EINTR) break;
    if (cpu >= 0.0) {
      const double now_cpu = cpu_seconds(pid);
      const auto now = std::chrono::steady_clock::now();
      if (now_cpu != cpu) {
        cpu = now_cpu;
        cpu_moved = now;
      } else if (std::chrono::duration<double>(now - cpu_moved).count() > stall_seconds) {
        ::close(fds[0]);
        return std::nullopt;  // (child's destructor kills it)
      }
    }
    if (polled <= 0) {
      try {
        check_interrupt();
      } catch (...) {
        ::close(fds[0]);
        throw;
      }
      continue;
    }
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // end of file: the child has finished or died
    bytes.insert(bytes.end(), buffer, buffer + n);
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  child.reaped = true;
  if (WIFSIGNALED(status)) {
    throw MesherCrashed(std::string(what) + " crashed inside CGAL's Mesh_3 (signal " +
                        std::to_string(WTERMSIG(status)) + ")");
  }
  if (bytes.empty()) throw GeometryError(std::string(what) + ": the meshing process ended without an answer");
  return decode(bytes);
}

}  // namespace

ShellMesh mesh_in_child(const std::function<ShellMesh()>& make, const char* what) {
  return *fork_and_mesh([&](bool) { return make(); }, what, false, 0.0);
}

ShellMesh mesh_in_child_threaded(const std::function<ShellMesh(bool threads)>& make, const char* what,
                                 double stall_seconds) {
  if (auto mesh = fork_and_mesh(make, what, true, stall_seconds)) return std::move(*mesh);
  return *fork_and_mesh(make, what, false, 0.0);
}

#endif

}  // namespace morphomap::detail

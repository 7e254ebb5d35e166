// See mesh_in_child.hpp. The protocol on the pipe: one status byte (0: a mesh follows, 1:
// InvalidInput, 2: GeometryError, 3: Interrupted), then either the message (its length, then its
// bytes) or the mesh (vertex and tetrahedron counts, then the four arrays' raw bytes).
#include "diffusion/mesh_in_child.hpp"

#include "common/interrupt_check.hpp"

#include <morphomap/errors.hpp>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#if defined(__unix__) || defined(__APPLE__)
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#define MORPHOMAP_HAVE_FORK 1
#endif

namespace morphomap::detail {

#ifndef MORPHOMAP_HAVE_FORK

ShellMesh mesh_in_child(const std::function<ShellMesh()>& make, const char*) { return make(); }

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

[[noreturn]] void run_child(int fd, const std::function<ShellMesh()>& make) {
  // The parent's handlers (Python's faulthandler, say) would report the crash as the parent's
  // own; the parent reports it. Ctrl-C reaches the parent, which ends the child.
  for (const int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) ::signal(sig, SIG_DFL);
  ::signal(SIGINT, SIG_IGN);
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

// fork(), one thread at a time in this process. fork() runs every library's prepare handler in the
// forking thread, and some are not safe to run twice at once: OpenBLAS's (loaded with SciPy) joins
// its worker threads, and two concurrent forks joined the same thread, so one waited forever
// (three Python threads meshing at once hung in about one run in two).
pid_t fork_one_at_a_time() {
  static std::mutex forking;
  const std::lock_guard<std::mutex> lock(forking);
  return ::fork();
}

}  // namespace

ShellMesh mesh_in_child(const std::function<ShellMesh()>& make, const char* what) {
  int fds[2];
  if (::pipe(fds) != 0) return make();  // no pipe to spare: mesh here
  const pid_t pid = fork_one_at_a_time();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return make();
  }
  if (pid == 0) {
    ::close(fds[0]);
    run_child(fds[1], make);
  }
  ::close(fds[1]);
  Child child{pid};
  std::vector<char> bytes;
  char buffer[1 << 16];
  for (;;) {
    pollfd ready{fds[0], POLLIN, 0};
    const int polled = ::poll(&ready, 1, 100);
    if (polled < 0 && errno != EINTR) break;
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

#endif

}  // namespace morphomap::detail

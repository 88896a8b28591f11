#include <shapectl/mesh/tetgen_runner.hpp>

#include <pthread.h>
#include <sys/wait.h>
#include <tetgen.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <stdexcept>

#include <shapectl/io/input_error.hpp>

namespace shapectl {

namespace {

// What TetGen's terminatetetgen() codes mean (see tetgen.h).
std::string tetgen_failure(int code) {
  switch (code) {
    case 1: return "out of memory";
    case 2: return "internal error";
    case 3: return "the surface intersects itself";
    case 4: return "a very small input feature size was detected";
    case 5: return "two very close input facets were detected";
    case 10: return "an input error was detected";
    default: return "error code " + std::to_string(code);
  }
}

// TetGen 1.5.0 (Debian's libtet) frees its memory twice when it fails: terminatetetgen() frees
// it and throws an int, then ~tetgenmesh frees it again while the exception unwinds, crashing
// the process. So TetGen runs in a child process, on a thread of its own: there an exception
// finds no handler, and std::terminate runs before any destructor, reporting the code.
// The child writes to a pipe: int failure code (0 = success), then on success int point count,
// int tet count, the points (3 doubles each) and the tets (4 ints each).
int tetgen_report_fd = -1;

void write_all(int fd, const void* data, std::size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) _exit(1);
    p += n;
    size -= static_cast<std::size_t>(n);
  }
}

[[noreturn]] void report_tetgen_failure() {
  int code = -1;
  try {
    std::rethrow_exception(std::current_exception());
  } catch (int c) {
    code = c;
  } catch (...) {
  }
  write_all(tetgen_report_fd, &code, sizeof code);
  _exit(0);
}

struct TetgenJob {
  tetgenbehavior* behavior;
  tetgenio* in;
  tetgenio* out;
};

void* run_tetgen_thread(void* job) {
  auto* j = static_cast<TetgenJob*>(job);
  tetrahedralize(j->behavior, j->in, j->out);
  return nullptr;
}

[[noreturn]] void tetgen_child(int fd, TetgenJob job) {
  tetgen_report_fd = fd;
  std::set_terminate(report_tetgen_failure);
  pthread_t thread;
  if (pthread_create(&thread, nullptr, run_tetgen_thread, &job) != 0) _exit(1);
  pthread_join(thread, nullptr);
  const tetgenio& out = *job.out;
  const int header[3] = {0, out.numberofpoints, out.numberoftetrahedra};
  write_all(fd, header, sizeof header);
  write_all(fd, out.pointlist, sizeof(REAL) * 3 * out.numberofpoints);
  write_all(fd, out.tetrahedronlist, sizeof(int) * 4 * out.numberoftetrahedra);
  _exit(0);
}

// Runs tetrahedralize(behavior, in) in a child process; TetGen failures become InputError.
TetgenOutput tetrahedralize_isolated(tetgenbehavior& behavior, tetgenio& in,
                                     const std::string& source) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("cannot create a pipe for TetGen");
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    throw std::runtime_error("cannot fork a process for TetGen");
  }
  if (pid == 0) {
    close(fds[0]);
    tetgenio out;
    tetgen_child(fds[1], {&behavior, &in, &out});
  }
  close(fds[1]);
  std::string bytes;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    bytes.append(buffer, static_cast<std::size_t>(n));
  }
  close(fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }

  int header[3] = {-1, 0, 0};
  std::memcpy(header, bytes.data(), std::min(bytes.size(), sizeof header));
  if (bytes.size() >= sizeof(int) && header[0] != 0)
    throw InputError(source, "", "TetGen failed: " + tetgen_failure(header[0]));
  const std::size_t points = header[1] > 0 ? header[1] : 0, tets = header[2] > 0 ? header[2] : 0;
  if (bytes.size() != sizeof header + sizeof(double) * 3 * points + sizeof(int) * 4 * tets)
    throw InputError(source, "",
                     "TetGen stopped unexpectedly (" +
                         (WIFSIGNALED(status)
                              ? "signal " + std::to_string(WTERMSIG(status))
                              : "exit code " + std::to_string(WEXITSTATUS(status))) +
                         ")");
  TetgenOutput result;
  result.points.resize(points);
  result.tets.resize(tets);
  const char* p = bytes.data() + sizeof header;
  for (auto& x : result.points) {
    std::memcpy(x.data(), p, 3 * sizeof(double));
    p += 3 * sizeof(double);
  }
  for (auto& t : result.tets) {
    std::memcpy(t.data(), p, 4 * sizeof(int));
    p += 4 * sizeof(int);
  }
  return result;
}

}  // namespace

TetgenOutput run_tetgen(const TriangleSurface& surface, const std::string& switches,
                        const std::string& source) {
  // tetgenio frees these arrays with delete[] when it dies.
  const int n = static_cast<int>(surface.vertices.size());
  tetgenio in;
  in.firstnumber = 0;
  in.numberofpoints = n;
  in.pointlist = new REAL[3 * n];
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) in.pointlist[3 * i + c] = surface.vertices[i][c];
  in.numberoffacets = static_cast<int>(surface.triangles.size());
  in.facetlist = new tetgenio::facet[in.numberoffacets];
  for (int f = 0; f < in.numberoffacets; ++f) {
    tetgenio::facet& facet = in.facetlist[f];
    tetgenio::init(&facet);
    facet.numberofpolygons = 1;
    facet.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&facet.polygonlist[0]);
    facet.polygonlist[0].numberofvertices = 3;
    facet.polygonlist[0].vertexlist = new int[3];
    for (int k = 0; k < 3; ++k) facet.polygonlist[0].vertexlist[k] = surface.triangles[f][k];
  }

  std::string text = switches;  // parse_commandline wants a mutable string
  tetgenbehavior behavior;
  if (!behavior.parse_commandline(text.data()))
    throw std::logic_error("TetGen rejected the switches " + text);
  return tetrahedralize_isolated(behavior, in, source);
}

}  // namespace shapectl

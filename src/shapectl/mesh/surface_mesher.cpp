#include <shapectl/mesh/surface_mesher.hpp>

#include <pthread.h>
#include <sys/wait.h>
#include <tetgen.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <map>
#include <sstream>
#include <string_view>

#include <shapectl/io/input_error.hpp>
#include <shapectl/mesh/mesh_limits.hpp>
#include <shapectl/mesh/text_lines.hpp>

namespace shapectl {

namespace {

// Collects a surface as the file lists it: merges vertices with equal coordinates, splits
// polygons into triangle fans, and finally drops vertices no face uses.
class SurfaceBuilder {
 public:
  explicit SurfaceBuilder(const std::string& name) : name_(name) {}
  void add_vertex(const Vec3& x) {
    if (static_cast<long>(unique_of_read_.size()) >= 3 * max_surface_triangles)
      throw InputError(name_, "", "more than " + std::to_string(3 * max_surface_triangles) +
                                      " vertices (the limit for a surface)");
    const auto [it, inserted] =
        merged_.emplace(std::array<double, 3>{x.x(), x.y(), x.z()}, int(surface_.vertices.size()));
    if (inserted) surface_.vertices.push_back(x);
    unique_of_read_.push_back(it->second);
  }
  int vertex_count() const { return static_cast<int>(unique_of_read_.size()); }
  // `corners` index the vertices in the order they were read; false if a vertex repeats.
  bool add_polygon(const std::vector<int>& corners) {
    if (static_cast<long>(surface_.triangles.size() + corners.size()) - 2 > max_surface_triangles)
      throw InputError(name_, "", "more than " + std::to_string(max_surface_triangles) +
                                      " triangles (the limit for a surface)");
    std::vector<int> unique;
    for (int c : corners) unique.push_back(unique_of_read_[c]);
    std::vector<int> sorted = unique;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return false;
    for (std::size_t k = 1; k + 1 < unique.size(); ++k)
      surface_.triangles.push_back({unique[0], unique[k], unique[k + 1]});
    return true;
  }
  TriangleSurface finish(const std::string& name) {
    if (surface_.triangles.empty()) throw InputError(name, "", "no faces");
    std::vector<int> new_index(surface_.vertices.size(), -1);
    for (const auto& t : surface_.triangles)
      for (int v : t) new_index[v] = 0;
    TriangleSurface out;
    for (std::size_t v = 0; v < surface_.vertices.size(); ++v)
      if (new_index[v] == 0) {
        new_index[v] = static_cast<int>(out.vertices.size());
        out.vertices.push_back(surface_.vertices[v]);
      }
    for (const auto& t : surface_.triangles)
      out.triangles.push_back({new_index[t[0]], new_index[t[1]], new_index[t[2]]});
    return out;
  }

 private:
  std::string name_;
  TriangleSurface surface_;
  std::map<std::array<double, 3>, int> merged_;
  std::vector<int> unique_of_read_;  // for each vertex read, its index in surface_.vertices
};

// OBJ: "v x y z" and "f a b c ..." (a may be "a/t/n" or "a//n", negative counts back);
// everything else (vt, vn, g, o, s, usemtl, ...) is ignored.
TriangleSurface read_obj(const std::string& name, const std::string& text) {
  TextLines in(name, text, TextLines::Comments::Hash);
  SurfaceBuilder builder(name);
  while (in.next()) {
    if (in[0] == "v") {
      if (in.size() < 4) in.fail("", "expected 'v x y z', found " + std::to_string(in.size() - 1) + " values");
      builder.add_vertex(in.point(1, ""));
    } else if (in[0] == "f") {
      if (in.size() < 4) in.fail("face", "expected at least 3 vertices");
      std::vector<int> corners;
      for (std::size_t k = 1; k < in.size(); ++k) {
        const std::string_view token = in[k].substr(0, in[k].find('/'));
        const long long index = in.integer(token, "face", "vertex index");
        const long long n = builder.vertex_count();
        const long long i = index < 0 ? n + index : index - 1;
        if (index == 0 || i < 0 || i >= n)
          in.fail("face", "vertex index " + std::to_string(index) + " out of range (" +
                              std::to_string(n) + " vertices so far)");
        corners.push_back(static_cast<int>(i));
      }
      if (!builder.add_polygon(corners)) in.fail("face", "uses the same vertex twice");
    }
  }
  return builder.finish(name);
}

// OFF: "OFF", "vertices faces edges", then "x y z" lines and "k i0 ... ik-1 [colour]" lines.
TriangleSurface read_off(const std::string& name, const std::string& text) {
  TextLines in(name, text, TextLines::Comments::Hash);
  in.next("the OFF header");
  if (in[0].size() < 3 || !in[0].ends_with("OFF"))
    in.fail("", "expected the OFF header, found '" + shown(in[0]) + "'");
  std::size_t first = 1;  // the counts may follow the header on the same line
  if (in.size() == 1) {
    in.next("the counts 'vertices faces edges'");
    first = 0;
  }
  if (in.size() < first + 2) in.fail("", "expected the counts 'vertices faces edges'");
  const long long vertices = in.count(first, "vertex count");
  const long long faces = in.count(first + 1, "face count");
  SurfaceBuilder builder(name);
  for (long long v = 0; v < vertices; ++v) {
    const std::string where = "vertex " + std::to_string(v);
    in.next(where + " of " + std::to_string(vertices));
    if (in.size() < 3) in.fail(where, "expected 'x y z'");
    builder.add_vertex(in.point(0, where));
  }
  for (long long f = 0; f < faces; ++f) {
    const std::string where = "face " + std::to_string(f);
    in.next(where + " of " + std::to_string(faces));
    const long long k = in.count(0, "corner count");
    if (k < 3 || static_cast<long long>(in.size()) < 1 + k)
      in.fail(where, "expected a corner count >= 3 followed by that many vertex indices");
    std::vector<int> corners;
    for (long long c = 1; c <= k; ++c) {
      const long long index = in.integer(c, where, "vertex index");
      if (index < 0 || index >= vertices)
        in.fail(where, "vertex index " + std::to_string(index) + " out of range (" +
                           std::to_string(vertices) + " vertices)");
      corners.push_back(static_cast<int>(index));
    }
    if (!builder.add_polygon(corners)) in.fail(where, "uses the same vertex twice");
  }
  return builder.finish(name);
}

// ASCII STL: "solid", then facets of "outer loop", three "vertex x y z", "endloop", "endfacet".
TriangleSurface read_ascii_stl(const std::string& name, const std::string& text) {
  TextLines in(name, text, TextLines::Comments::Hash);
  SurfaceBuilder builder(name);
  std::vector<int> corners;
  bool in_facet = false;
  while (in.next()) {
    const std::string_view word = in[0];
    if (word == "facet") {
      if (in_facet) in.fail("", "'facet' before 'endfacet'");
      in_facet = true;
      corners.clear();
    } else if (word == "vertex") {
      if (!in_facet) in.fail("", "'vertex' outside a facet");
      if (in.size() != 4) in.fail("", "expected 'vertex x y z'");
      builder.add_vertex(in.point(1, "vertex"));
      corners.push_back(builder.vertex_count() - 1);
    } else if (word == "endfacet") {
      if (!in_facet) in.fail("", "'endfacet' without 'facet'");
      if (corners.size() != 3)
        in.fail("facet", "expected 3 vertices, found " + std::to_string(corners.size()));
      if (!builder.add_polygon(corners)) in.fail("facet", "uses the same vertex twice");
      in_facet = false;
    } else if (word != "solid" && word != "endsolid" && word != "outer" && word != "endloop") {
      in.fail("", "expected an STL keyword (facet, vertex, endfacet, ...), found '" +
                      shown(word) + "'");
    }
  }
  if (in_facet) in.fail("", "file ends inside a facet");
  return builder.finish(name);
}

// Binary STL: 80-byte header, uint32 count, then per triangle 12 float32 (normal, 3 vertices)
// and a uint16, little-endian.
TriangleSurface read_binary_stl(const std::string& name, const std::string& bytes) {
  auto read_float = [&](std::size_t at) {
    std::uint32_t bits = 0;
    for (int b = 3; b >= 0; --b) bits = (bits << 8) | static_cast<unsigned char>(bytes[at + b]);
    float value;
    std::memcpy(&value, &bits, sizeof value);
    return static_cast<double>(value);
  };
  const std::size_t count = (bytes.size() - 84) / 50;
  if (count > static_cast<std::size_t>(max_surface_triangles))
    throw InputError(name, "", std::to_string(count) + " triangles, more than the limit of " +
                                   std::to_string(max_surface_triangles) + " for a surface");
  SurfaceBuilder builder(name);
  for (std::size_t t = 0; t < count; ++t) {
    std::vector<int> corners;
    for (int c = 0; c < 3; ++c) {
      const std::size_t at = 84 + 50 * t + 12 + 12 * c;
      const Vec3 x(read_float(at), read_float(at + 4), read_float(at + 8));
      if (!x.allFinite())
        throw InputError(name, "triangle " + std::to_string(t), "vertex is not finite");
      builder.add_vertex(x);
      corners.push_back(builder.vertex_count() - 1);
    }
    if (!builder.add_polygon(corners))
      throw InputError(name, "triangle " + std::to_string(t), "uses the same vertex twice");
  }
  return builder.finish(name);
}

// A binary STL is exactly 84 + 50 n bytes for the n its header states; ASCII starts "solid".
TriangleSurface read_stl(const std::string& name, const std::string& bytes) {
  if (bytes.size() >= 84) {
    std::uint32_t count = 0;
    for (int b = 3; b >= 0; --b) count = (count << 8) | static_cast<unsigned char>(bytes[80 + b]);
    if (bytes.size() == 84 + 50 * std::uint64_t(count)) return read_binary_stl(name, bytes);
  }
  const std::size_t start = bytes.find_first_not_of(" \t\r\n");
  if (start != std::string::npos && bytes.compare(start, 5, "solid") == 0)
    return read_ascii_stl(name, bytes);
  throw InputError(name, "",
                   "neither ASCII STL (starting with 'solid') nor binary STL (84 + 50 bytes per "
                   "triangle; this file has " + std::to_string(bytes.size()) + " bytes)");
}

std::string lowercase(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string shown_point(const Vec3& x) {
  std::ostringstream s;
  s << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
  return s.str();
}

// Every edge must be shared by exactly two triangles, or TetGen cannot tell inside from out.
void expect_closed(const TriangleSurface& surface, const std::string& source) {
  std::map<std::pair<int, int>, int> uses;
  for (const auto& t : surface.triangles)
    for (int k = 0; k < 3; ++k) uses[std::minmax(t[k], t[(k + 1) % 3])]++;
  for (const auto& [edge, count] : uses)
    if (count != 2)
      throw InputError(source, "",
                       "the surface is not closed: edge " + shown_point(surface.vertices[edge.first]) +
                           "-" + shown_point(surface.vertices[edge.second]) + " belongs to " +
                           std::to_string(count) + " triangle" + (count == 1 ? "" : "s") +
                           ", expected 2");
}

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

void* run_tetgen(void* job) {
  auto* j = static_cast<TetgenJob*>(job);
  tetrahedralize(j->behavior, j->in, j->out);
  return nullptr;
}

[[noreturn]] void tetgen_child(int fd, TetgenJob job) {
  tetgen_report_fd = fd;
  std::set_terminate(report_tetgen_failure);
  pthread_t thread;
  if (pthread_create(&thread, nullptr, run_tetgen, &job) != 0) _exit(1);
  pthread_join(thread, nullptr);
  const tetgenio& out = *job.out;
  const int header[3] = {0, out.numberofpoints, out.numberoftetrahedra};
  write_all(fd, header, sizeof header);
  write_all(fd, out.pointlist, sizeof(REAL) * 3 * out.numberofpoints);
  write_all(fd, out.tetrahedronlist, sizeof(int) * 4 * out.numberoftetrahedra);
  _exit(0);
}

struct TetgenResult {
  std::vector<Vec3> points;
  std::vector<std::array<int, 4>> tets;
};

// Runs tetrahedralize(behavior, in) in a child process; TetGen failures become InputError.
TetgenResult tetrahedralize_isolated(tetgenbehavior& behavior, tetgenio& in,
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
                         (WIFSIGNALED(status) ? "signal " + std::to_string(WTERMSIG(status))
                                              : "exit code " + std::to_string(WEXITSTATUS(status))) +
                         ")");
  TetgenResult result;
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

bool is_surface_file(const std::filesystem::path& file) {
  const std::string extension = lowercase(file.extension().string());
  return extension == ".obj" || extension == ".stl" || extension == ".off";
}

TriangleSurface read_surface(const std::filesystem::path& file) {
  const std::string extension = lowercase(file.extension().string());
  const std::string name = file.string();
  if (!is_surface_file(file))
    throw InputError(name, "", "unknown surface format '" + extension + "' (supported: .obj, .stl, .off)");
  const std::string text = read_text_file(file);
  if (extension == ".obj") return read_obj(name, text);
  if (extension == ".stl") return read_stl(name, text);
  return read_off(name, text);
}

namespace {

// The volume a closed triangle surface encloses (divergence theorem), m^3.
double enclosed_volume(const TriangleSurface& surface) {
  double six_volume = 0;
  for (const auto& t : surface.triangles)
    six_volume += surface.vertices[t[0]].dot(surface.vertices[t[1]].cross(surface.vertices[t[2]]));
  return std::abs(six_volume) / 6;
}

}  // namespace

TetMesh tetrahedralize_surface(const TriangleSurface& surface, const SurfaceMeshOptions& options,
                               const std::string& source) {
  const double ratio = options.max_radius_edge_ratio, volume = options.max_tet_volume;
  const std::string option_file = options.origin_file.empty() ? source : options.origin_file;
  auto option = [&](const std::string& name) {
    return options.origin_path.empty() ? name : options.origin_path + "." + name;
  };
  if (!(std::isfinite(ratio) && (ratio == 0 || ratio >= 1)))
    throw InputError(option_file, option("max_radius_edge_ratio"), "0 (off) or a ratio >= 1", ratio);
  if (!(std::isfinite(volume) && volume >= 0))
    throw InputError(option_file, option("max_tet_volume"), "0 (no bound) or a positive volume in m^3", volume);
  const int n = static_cast<int>(surface.vertices.size());
  for (const auto& t : surface.triangles)
    for (int v : t)
      if (v < 0 || v >= n)
        throw InputError(source, "", "triangle vertex " + std::to_string(v) + " out of range");
  // TetGen's exact predicates overflow on huge coordinates (products of four of them).
  for (int i = 0; i < n; ++i)
    if (!(surface.vertices[i].cwiseAbs().maxCoeff() <= 1e6))
      throw InputError(source, "vertex " + std::to_string(i), "coordinates within 1e6 m of the origin",
                       shown_point(surface.vertices[i]));
  if (surface.triangles.empty()) throw InputError(source, "", "no triangles");
  if (static_cast<long>(surface.triangles.size()) > max_surface_triangles)
    throw InputError(source, "", "more than " + std::to_string(max_surface_triangles) + " triangles");
  expect_closed(surface, source);
  // Refuse a volume bound that asks for more tets than a mesh may have, before TetGen runs.
  const double enclosed = enclosed_volume(surface);
  if (volume > 0 && enclosed / volume > max_tetgen_volume_ratio) {
    std::ostringstream expected;
    expected << "0 (no bound) or at least " << enclosed / max_tetgen_volume_ratio
             << " m^3 (the surface " << source << " encloses " << enclosed << " m^3; at most "
             << max_tetgen_volume_ratio << " times smaller)";
    throw InputError(option_file, option("max_tet_volume"), expected.str(), volume);
  }

  // tetgenio frees these arrays with delete[] when it dies.
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

  // p: the input is a surface; z: number from 0; Q: quiet.
  std::ostringstream switches;
  switches.precision(17);
  switches << "pzQS" << max_tetgen_added_points;
  if (ratio > 0) switches << "q" << ratio;
  if (volume > 0) switches << "a" << volume;
  if (options.keep_surface) switches << "Y";
  std::string text = switches.str();
  tetgenbehavior behavior;
  if (!behavior.parse_commandline(text.data()))
    throw std::logic_error("TetGen rejected the switches " + text);
  TetgenResult out = tetrahedralize_isolated(behavior, in, source);
  // TetGen quietly stops refining when -S runs out: the mesh would not meet the options.
  if (static_cast<long>(out.points.size()) - n >= max_tetgen_added_points)
    throw InputError(option_file, options.origin_path,
                     "TetGen needed more than " + std::to_string(max_tetgen_added_points) +
                         " added points for these options; allow larger or less regular "
                         "tets (a larger max_tet_volume or max_radius_edge_ratio)");
  if (static_cast<long>(out.tets.size()) > max_mesh_tets)
    throw InputError(source, "", "TetGen made " + std::to_string(out.tets.size()) +
                                     " tetrahedra, more than the limit of " + std::to_string(max_mesh_tets));

  // TetGen keeps the input points first; a surface vertex it dropped would break that promise.
  for (int i = 0; i < n; ++i)
    if (i >= static_cast<int>(out.points.size()) || out.points[i] != surface.vertices[i])
      throw InputError(source, "vertex " + std::to_string(i), "TetGen moved or dropped it");
  // TetGen 1.5 writes positively oriented tets (volume of (a, b, c, d) > 0), as TetMesh wants.
  return TetMesh(std::move(out.points), std::move(out.tets), source);
}

TetMesh mesh_surface(const std::filesystem::path& file, const SurfaceMeshOptions& options) {
  return tetrahedralize_surface(read_surface(file), options, file.string());
}

}  // namespace shapectl

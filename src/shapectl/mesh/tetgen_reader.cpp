#include <shapectl/mesh/tetgen_reader.hpp>

#include <Eigen/LU>
#include <sstream>
#include <string>
#include <vector>

#include <shapectl/io/input_error.hpp>
#include <shapectl/mesh/mesh_limits.hpp>
#include <shapectl/mesh/text_lines.hpp>

namespace shapectl {

namespace {

// Reads a non-negative header field no larger than `max`.
long long header_field(const TextLines& in, std::size_t i, const std::string& what, long long max) {
  const long long value = in.integer(i, "header", what);
  if (value < 0 || value > max)
    in.fail("header",
            what + " must be 0.." + std::to_string(max) + ", got " + std::to_string(value));
  return value;
}

struct Points {
  std::vector<Vec3> positions;
  long long first = 0;  // number of the first point: 0 or 1
};

// "<points> 3 <attributes> <markers>", then "<number> x y z [attributes] [marker]" per point.
Points read_node_file(const std::filesystem::path& file) {
  TextLines in(file.string(), read_text_file(file), TextLines::Comments::Hash);
  in.next("the header '<points> <dimension> <attributes> <boundary markers>'");
  if (in.size() < 2 || in.size() > 4)
    in.fail("header", "expected '<points> <dimension> [<attributes> [<boundary markers>]]'");
  const long long n = header_field(in, 0, "point count", max_mesh_nodes);
  const long long dimension = in.integer(1, "header", "dimension");
  if (dimension != 3) in.fail("header", "dimension must be 3, got " + std::to_string(dimension));
  const long long attributes = in.size() > 2 ? header_field(in, 2, "attribute count", 1000) : 0;
  const long long markers = in.size() > 3 ? header_field(in, 3, "boundary marker flag", 1) : 0;
  if (n == 0) in.fail("header", "no points (points kept in a .poly file are not supported)");
  const std::size_t values = 4 + attributes + markers;
  Points points;
  for (long long i = 0; i < n; ++i) {
    in.next("point " + std::to_string(i + 1) + " of " + std::to_string(n));
    const long long number = in.integer(0, "", "point number");
    const std::string where = "point " + std::to_string(number);
    if (i == 0) {
      if (number != 0 && number != 1) in.fail(where, "the first point must be numbered 0 or 1");
      points.first = number;
    }
    if (number != points.first + i)
      in.fail(where, "expected point " + std::to_string(points.first + i) +
                         " (points are numbered consecutively)");
    in.expect_values(values, where,
                     "number, x, y, z, " + std::to_string(attributes) + " attributes, " +
                         std::to_string(markers) + " markers");
    points.positions.push_back(in.point(1, where));
  }
  return points;
}

struct Elements {
  std::vector<std::array<int, 4>> tets;
  std::vector<int> lines;          // line of each tet, for messages
  std::vector<long long> numbers;  // the file's number of each tet
};

// "<tets> <4 or 10> <region attribute>", then "<number> n0 n1 n2 n3 [...] [attribute]" per tet.
Elements read_ele_file(const std::filesystem::path& file, const Points& points) {
  TextLines in(file.string(), read_text_file(file), TextLines::Comments::Hash);
  in.next("the header '<tetrahedra> <nodes per tetrahedron> <region attribute>'");
  if (in.size() < 2 || in.size() > 3)
    in.fail("header", "expected '<tetrahedra> <nodes per tetrahedron> [<region attribute>]'");
  const long long n = header_field(in, 0, "tetrahedron count", max_mesh_tets);
  const long long corners = in.integer(1, "header", "nodes per tetrahedron");
  if (corners != 4 && corners != 10)
    in.fail("header", "nodes per tetrahedron must be 4 or 10, got " + std::to_string(corners));
  const long long attributes =
      in.size() > 2 ? header_field(in, 2, "region attribute count", 1000) : 0;
  const long long node_count = static_cast<long long>(points.positions.size());
  Elements elements;
  for (long long e = 0; e < n; ++e) {
    in.next("tetrahedron " + std::to_string(e + 1) + " of " + std::to_string(n));
    const long long number = in.integer(0, "", "tetrahedron number");
    const std::string where = "element " + std::to_string(number);
    in.expect_values(1 + corners + attributes, where,
                     "number, " + std::to_string(corners) + " nodes, " +
                         std::to_string(attributes) + " attributes");
    std::array<int, 4> tet;
    for (int a = 0; a < 4; ++a) {
      const long long node = in.integer(1 + a, where, "node number");
      if (node < points.first || node >= points.first + node_count)
        in.fail(where, "node " + std::to_string(node) + " out of range (" + file.stem().string() +
                           ".node has points " + std::to_string(points.first) + ".." +
                           std::to_string(points.first + node_count - 1) + ")");
      tet[a] = static_cast<int>(node - points.first);
    }
    elements.tets.push_back(tet);
    elements.lines.push_back(in.line());
    elements.numbers.push_back(number);
  }
  if (n == 0) in.fail("header", "no tetrahedra");
  return elements;
}

double signed_volume(const std::vector<Vec3>& x, const std::array<int, 4>& t) {
  Mat3 Dm;
  for (int c = 0; c < 3; ++c) Dm.col(c) = x[t[c + 1]] - x[t[0]];
  return Dm.determinant() / 6;
}

}  // namespace

TetMesh read_tetgen(const std::filesystem::path& file) {
  std::filesystem::path base = file;
  if (file.extension() == ".node" || file.extension() == ".ele") base.replace_extension();
  const std::filesystem::path node_file = base.string() + ".node";
  const std::filesystem::path ele_file = base.string() + ".ele";
  Points points = read_node_file(node_file);
  Elements elements = read_ele_file(ele_file, points);

  // TetGen versions disagree on orientation: a file whose tets are all negative is turned over
  // by swapping two nodes of every tet; a negative tet among positive ones is an error.
  bool all_negative = true;
  for (const auto& t : elements.tets) all_negative &= signed_volume(points.positions, t) < 0;
  for (std::size_t e = 0; e < elements.tets.size(); ++e) {
    auto& t = elements.tets[e];
    if (all_negative) std::swap(t[2], t[3]);
    const double volume = signed_volume(points.positions, t);
    if (volume < 0) {
      std::ostringstream problem;
      problem << "inverted tetrahedron (volume " << volume << ") among positively oriented ones";
      throw InputError(ele_file.string() + ":" + std::to_string(elements.lines[e]),
                       "element " + std::to_string(elements.numbers[e]), problem.str());
    }
  }
  return TetMesh(std::move(points.positions), std::move(elements.tets), ele_file.string());
}

}  // namespace shapectl

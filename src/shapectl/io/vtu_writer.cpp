#include <shapectl/io/vtu_writer.hpp>

#include <limits>
#include <sstream>
#include <stdexcept>

#include <shapectl/io/atomic_file.hpp>

namespace shapectl {

namespace {

// Field names go into XML attributes.
std::string xml_escaped(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '&') out += "&amp;";
    else if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

void write_vectors(std::ostream& out, const Positions& values) {
  for (Eigen::Index i = 0; i < values.size(); i += 3)
    out << values[i] << ' ' << values[i + 1] << ' ' << values[i + 2] << '\n';
}

void check_sizes(const Positions& positions, const std::vector<std::array<int, 4>>& tets,
                 const std::vector<VtuNodeField>& node_fields) {
  if (positions.size() % 3 != 0)
    throw std::invalid_argument("write_vtu: positions size " + std::to_string(positions.size()) +
                                " is not a multiple of 3");
  const long n = static_cast<long>(positions.size() / 3);
  for (const auto& t : tets)
    for (int v : t)
      if (v < 0 || v >= n)
        throw std::invalid_argument("write_vtu: tet node " + std::to_string(v) + " out of range (" +
                                    std::to_string(n) + " nodes)");
  if (!positions.allFinite()) throw std::invalid_argument("write_vtu: a position is not finite");
  for (const auto& f : node_fields) {
    if (f.values.size() != positions.size())
      throw std::invalid_argument("write_vtu: field '" + f.name + "' has size " +
                                  std::to_string(f.values.size()) + ", expected " +
                                  std::to_string(positions.size()));
    if (!f.values.allFinite())
      throw std::invalid_argument("write_vtu: field '" + f.name + "' is not finite");
  }
}

}  // namespace

std::string vtu_text(const Positions& positions, const std::vector<std::array<int, 4>>& tets,
                     const std::vector<VtuNodeField>& node_fields) {
  check_sizes(positions, tets, node_fields);
  std::ostringstream out;
  out.precision(std::numeric_limits<double>::max_digits10);
  const std::size_t n = static_cast<std::size_t>(positions.size() / 3);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n"
      << "<UnstructuredGrid>\n"
      << "<Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << tets.size() << "\">\n";
  out << "<PointData>\n";
  for (const auto& f : node_fields) {
    out << "<DataArray type=\"Float64\" Name=\"" << xml_escaped(f.name)
        << "\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    write_vectors(out, f.values);
    out << "</DataArray>\n";
  }
  out << "</PointData>\n<Points>\n"
      << "<DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n";
  write_vectors(out, positions);
  out << "</DataArray>\n</Points>\n<Cells>\n"
      << "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& t : tets) out << t[0] << ' ' << t[1] << ' ' << t[2] << ' ' << t[3] << '\n';
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t e = 1; e <= tets.size(); ++e) out << 4 * e << '\n';
  // 10 is VTK_TETRA.
  out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (std::size_t e = 0; e < tets.size(); ++e) out << "10\n";
  out << "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  return out.str();
}

void write_vtu(const std::filesystem::path& file, const Positions& positions,
               const std::vector<std::array<int, 4>>& tets,
               const std::vector<VtuNodeField>& node_fields) {
  write_file_atomically(file, vtu_text(positions, tets, node_fields));
}

}  // namespace shapectl

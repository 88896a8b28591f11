#include <shapectl/mesh/msh_reader.hpp>

#include <Eigen/LU>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include <shapectl/io/input_error.hpp>
#include <shapectl/mesh/mesh_limits.hpp>
#include <shapectl/mesh/text_lines.hpp>

namespace shapectl {

namespace {

// A line that starts a section, such as "$Nodes" or "$EndNodes".
bool is_section(const TextLines& in) { return in.size() > 0 && in[0].starts_with('$'); }

// The next line, which must hold data (not a $Section marker): `expected` says what for.
void next_data(TextLines& in, const std::string& expected) {
  in.next(expected);
  if (is_section(in)) in.fail("", "expected " + expected + ", found " + shown(in[0]));
}

constexpr long long linear_tet_type = 4;

struct MshContent {
  std::vector<Vec3> positions;
  std::unordered_map<long long, int> index_of_tag;
  std::vector<std::array<int, 4>> tets;
  std::vector<int> tet_lines;       // line of each tet in the file, for messages
  std::vector<long long> tet_tags;  // Gmsh element tag of each tet
};

// Reads "$MeshFormat / version file-type data-size / $EndMeshFormat"; returns 2 or 4.
int read_format(TextLines& in) {
  if (!in.next()) throw InputError(in.name(), "", "empty file, expected a Gmsh MSH file");
  if (in[0] != "$MeshFormat")
    in.fail("", "expected $MeshFormat (a Gmsh MSH file), found '" + shown(in[0]) + "'");
  next_data(in, "the format line 'version file-type data-size'");
  if (in.size() < 2) in.expect_values(3, "", "version, file-type, data-size");
  if (in.integer(1, "", "file-type") != 0) in.fail("", "binary MSH not supported, save as ASCII");
  int version = 0;
  if (in[0] == "2" || in[0] == "2.0" || in[0] == "2.1" || in[0] == "2.2") version = 2;
  if (in[0] == "4.1") version = 4;
  if (version == 0)
    in.fail("", "unsupported MSH version " + shown(in[0]) + " (supported: 2.2 and 4.1 ASCII)");
  if (!in.next() || in[0] != "$EndMeshFormat")
    in.fail("", "expected $EndMeshFormat after the format line");
  return version;
}

void add_node(TextLines& in, MshContent& msh, long long tag, const Vec3& x) {
  const std::string where = "node " + std::to_string(tag);
  if (static_cast<long>(msh.positions.size()) >= max_mesh_nodes)
    in.fail(where, "more than " + std::to_string(max_mesh_nodes) + " nodes (the limit for a mesh)");
  const auto [it, inserted] = msh.index_of_tag.emplace(tag, static_cast<int>(msh.positions.size()));
  if (!inserted) in.fail(where, "tag appears twice in $Nodes");
  msh.positions.push_back(x);
}

// A tetrahedron's four node tags, from tokens first..first+3 of the current line.
void add_tet(TextLines& in, MshContent& msh, long long tag, std::size_t first) {
  const std::string where = "element " + std::to_string(tag);
  if (static_cast<long>(msh.tets.size()) >= max_mesh_tets)
    in.fail(where,
            "more than " + std::to_string(max_mesh_tets) + " tetrahedra (the limit for a mesh)");
  std::array<int, 4> tet;
  for (int a = 0; a < 4; ++a) {
    const long long node = in.integer(first + a, where, "node tag");
    const auto it = msh.index_of_tag.find(node);
    if (it == msh.index_of_tag.end())
      in.fail(where, "node " + std::to_string(node) + " not found in $Nodes (mesh has " +
                         std::to_string(msh.positions.size()) + " nodes)");
    tet[a] = it->second;
    for (int b = 0; b < a; ++b)
      if (tet[b] == tet[a]) in.fail(where, "node " + std::to_string(node) + " appears twice");
  }
  msh.tets.push_back(tet);
  msh.tet_lines.push_back(in.line());
  msh.tet_tags.push_back(tag);
}

void expect_end(TextLines& in, const std::string& end, const std::string& after) {
  in.next(end);
  if (in[0] != end)
    in.fail("", "expected " + end + " after " + after + ", found '" + shown(in[0]) + "'");
}

// MSH 2.2 $Nodes and $Elements: a count n, then n lines, each read by `read_item()`.
// `section` is "Nodes" or "Elements", `item` "node" or "element" (for messages).
template <class ReadItem>
void read_list_2(TextLines& in, const std::string& section, const std::string& item,
                 ReadItem read_item) {
  next_data(in, "the " + item + " count");
  in.expect_values(1, "", item + " count");
  const long long n = in.count(0, item + " count");
  const std::string count_line = "count on line " + std::to_string(in.line());
  for (long long i = 0; i < n; ++i) {
    next_data(in, item + " " + std::to_string(i + 1) + " of " + std::to_string(n) + " (" +
                      count_line + ")");
    read_item();
  }
  expect_end(in, "$End" + section, std::to_string(n) + " " + item + "s (" + count_line + ")");
}

// MSH 2.2: "n" then n lines "tag x y z".
void read_nodes_2(TextLines& in, MshContent& msh) {
  read_list_2(in, "Nodes", "node", [&] {
    in.expect_values(4, "", "node tag, x, y, z");
    const long long tag = in.integer(0, "", "node tag");
    add_node(in, msh, tag, in.point(1, "node " + std::to_string(tag)));
  });
}

// MSH 2.2: "n" then n lines "tag type ntags tag... node...".
void read_elements_2(TextLines& in, MshContent& msh) {
  read_list_2(in, "Elements", "element", [&] {
    if (in.size() < 3) in.fail("", "expected 'tag type tag-count tags... nodes...'");
    const long long tag = in.integer(0, "", "element tag");
    const std::string where = "element " + std::to_string(tag);
    const long long type = in.integer(1, where, "element type");
    const long long tags = in.integer(2, where, "tag count");
    if (tags < 0 || tags > static_cast<long long>(in.size()) - 3)
      in.fail(where, "tag count " + std::to_string(tags) + " does not fit the line's " +
                         std::to_string(in.size()) + " values");
    if (type != linear_tet_type) return;
    in.expect_values(3 + tags + 4, where,
                     "tag, type, tag count, " + std::to_string(tags) + " tags, 4 node tags");
    add_tet(in, msh, tag, 3 + tags);
  });
}

// MSH 4.1 $Nodes and $Elements: "blocks n min-tag max-tag", then per block a header line
// "entity-dimension entity-tag <third> count" and its lines, which `read_block(block)` reads,
// returning the block's count. `section` is "Nodes" or "Elements", `item` "node" or "element".
template <class ReadBlock>
void read_blocks_4(TextLines& in, const std::string& section, const std::string& item,
                   const std::string& third, ReadBlock read_block) {
  next_data(in, "the $" + section + " header 'blocks " + item + "s min-tag max-tag'");
  in.expect_values(4, "", "blocks, " + item + "s, min-tag, max-tag");
  const long long blocks = in.count(0, "block count");
  const long long n = in.count(1, item + " count");
  const int count_line = in.line();
  long long read = 0;
  for (long long b = 0; b < blocks; ++b) {
    const std::string block =
        item + " block " + std::to_string(b + 1) + " of " + std::to_string(blocks);
    next_data(in, block + " (count on line " + std::to_string(count_line) + ")");
    in.expect_values(4, block, "entity dimension, entity tag, " + third + ", " + item + " count");
    read += read_block(block);
  }
  if (read != n)
    in.fail("", "the $" + section + " header on line " + std::to_string(count_line) + " says " +
                    std::to_string(n) + " " + item + "s, its blocks hold " + std::to_string(read));
  expect_end(in, "$End" + section,
             std::to_string(blocks) + " " + item + " blocks (count on line " +
                 std::to_string(count_line) + ")");
}

// MSH 4.1: per block "dim entity parametric count", count lines of tags, then count lines
// "x y z" (plus dim parametric coordinates).
void read_nodes_4(TextLines& in, MshContent& msh) {
  read_blocks_4(in, "Nodes", "node", "parametric", [&](const std::string& block) {
    const long long dim = in.integer(0, block, "entity dimension");
    const long long parametric = in.integer(2, block, "parametric flag");
    const long long in_block = in.count(3, "node count");
    if (dim < 0 || dim > 3)
      in.fail(block, "entity dimension must be 0..3, got " + std::to_string(dim));
    if (parametric != 0 && parametric != 1)
      in.fail(block, "parametric flag must be 0 or 1, got " + std::to_string(parametric));
    const int header_line = in.line();
    std::vector<long long> tags;
    for (long long i = 0; i < in_block; ++i) {
      next_data(in, "node tag " + std::to_string(i + 1) + " of " + std::to_string(in_block) +
                        " (count on line " + std::to_string(header_line) + ")");
      in.expect_values(1, block, "node tag");
      tags.push_back(in.integer(0, block, "node tag"));
    }
    const std::size_t values = 3 + (parametric ? dim : 0);
    for (long long tag : tags) {
      const std::string where = "node " + std::to_string(tag);
      next_data(in, "the coordinates of node " + std::to_string(tag));
      in.expect_values(values, where, values == 3 ? "x, y, z" : "x, y, z, parametric u, v, w");
      add_node(in, msh, tag, in.point(0, where));
    }
    return in_block;
  });
}

// MSH 4.1: per block "dim entity type count", then count lines "tag node...".
void read_elements_4(TextLines& in, MshContent& msh) {
  read_blocks_4(in, "Elements", "element", "element type", [&](const std::string& block) {
    const long long type = in.integer(2, block, "element type");
    const long long in_block = in.count(3, "element count");
    const int header_line = in.line();
    for (long long i = 0; i < in_block; ++i) {
      next_data(in, "element " + std::to_string(i + 1) + " of " + std::to_string(in_block) +
                        " in the block on line " + std::to_string(header_line));
      const long long tag = in.integer(0, block, "element tag");
      if (type != linear_tet_type) continue;
      in.expect_values(5, "element " + std::to_string(tag), "element tag, 4 node tags");
      add_tet(in, msh, tag, 1);
    }
    return in_block;
  });
}

// Sections this reader does not need ($PhysicalNames, $Entities, $NodeData, ...).
void skip_section(TextLines& in) {
  const std::string end = "$End" + std::string(in[0].substr(1));
  const int start = in.line();
  while (in.next())
    if (in[0] == end) return;
  in.fail("", "file ends early: the section started on line " + std::to_string(start) + " has no " +
                  end);
}

}  // namespace

TetMesh read_msh(const std::filesystem::path& file) {
  TextLines in(file.string(), read_text_file(file), TextLines::Comments::None);
  const int version = read_format(in);
  MshContent msh;
  bool has_nodes = false, has_elements = false;
  while (in.next()) {
    if (in[0] == "$Nodes" && !has_nodes) {
      version == 2 ? read_nodes_2(in, msh) : read_nodes_4(in, msh);
      has_nodes = true;
    } else if (in[0] == "$Elements" && has_nodes && !has_elements) {
      version == 2 ? read_elements_2(in, msh) : read_elements_4(in, msh);
      has_elements = true;
    } else if (in[0] == "$Nodes" || in[0] == "$Elements") {
      in.fail("", std::string(in[0]) + (has_nodes ? " appears twice" : " before $Nodes"));
    } else if (in.size() == 1 && is_section(in) && !in[0].starts_with("$End")) {
      skip_section(in);
    } else {
      in.fail("", "expected a section such as $Nodes or $Elements, found '" + shown(in[0]) + "'");
    }
  }
  if (!has_nodes) throw InputError(in.name(), "", "no $Nodes section");
  if (!has_elements) throw InputError(in.name(), "", "no $Elements section");
  if (msh.tets.empty())
    throw InputError(in.name(), "",
                     "no linear tetrahedra (element type 4); mesh the volume in 3D and save again");
  // Gmsh writes positive tets; name the line of any that is not (TetMesh rechecks degeneracy).
  for (std::size_t e = 0; e < msh.tets.size(); ++e) {
    const auto& t = msh.tets[e];
    const auto& x = msh.positions;
    Mat3 Dm;
    for (int c = 0; c < 3; ++c) Dm.col(c) = x[t[c + 1]] - x[t[0]];
    const double volume = Dm.determinant() / 6;
    if (volume < 0) {
      std::ostringstream problem;
      problem << "inverted tetrahedron (volume " << volume << ")";
      throw InputError(in.name() + ":" + std::to_string(msh.tet_lines[e]),
                       "element " + std::to_string(msh.tet_tags[e]), problem.str());
    }
  }
  return TetMesh(std::move(msh.positions), std::move(msh.tets), in.name());
}

}  // namespace shapectl

#pragma once
// Reads TetGen's .node/.ele mesh pair.
#include <filesystem>

#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl {

// `file` names foo.node, foo.ele or the base path foo; both files are read. Indices are 0- or
// 1-based as the first point number in foo.node says; node i of the mesh is the i-th point of
// foo.node. Point attributes, boundary markers, region attributes and '#' comments are allowed
// and ignored; for 10-node tets the four corners are kept. Coordinates are taken as metres.
// A file whose tets are all negatively oriented (older TetGen versions) has two nodes of every
// tet swapped; a single inverted tet among positive ones is an error.
// Throws InputError naming the file, line and element.
TetMesh read_tetgen(const std::filesystem::path& file);

}  // namespace shapectl

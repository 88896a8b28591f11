#pragma once
// Writes tetrahedral meshes as VTK XML UnstructuredGrid (.vtu) files for ParaView.
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

struct VtuNodeField {
  std::string name;  // e.g. "displacement"
  Positions values;  // one 3-vector per node, stacked [v0; v1; ...], size 3n
};

// The text of an ASCII .vtu of linear tets (arguments as for write_vtu), e.g. to commit it
// together with another file (io/atomic_file.hpp).
std::string vtu_text(const Positions& positions, const std::vector<std::array<int, 4>>& tets,
                     const std::vector<VtuNodeField>& node_fields = {});

// Writes an ASCII .vtu of linear tets: `positions` stacked [x0; x1; ...] in metres (size 3n),
// `tets` indexing them, and per-node vector fields. The file is written beside its target and
// renamed over it, so a failure never leaves a half-written or damaged file behind.
// Throws InputError naming the file if it cannot be written (e.g. its directory is missing),
// std::invalid_argument if sizes or indices do not match or a number is not finite.
void write_vtu(const std::filesystem::path& file, const Positions& positions,
               const std::vector<std::array<int, 4>>& tets,
               const std::vector<VtuNodeField>& node_fields = {});

}  // namespace shapectl

#pragma once
// --surface OUT.ply|OUT.obj of `statics` and `solve`: the deformed surface (io/surface_writer).
#include <string>

#include <CLI/CLI.hpp>

#include <shapectl/io/atomic_file.hpp>
#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl::cli {

void add_surface_option(CLI::App& cmd, std::string& file);
// Checks the extension before any work: InputError naming --surface of `command` unless it is
// .ply or .obj. Nothing to check when `file` is empty.
void check_surface_option(const std::string& command, const std::string& file);
// The file to write with the others (atomically), in the format its extension names.
FileContent surface_file(const std::string& file, const TetMesh& mesh, const Positions& positions);

}  // namespace shapectl::cli

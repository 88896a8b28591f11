#pragma once
// Sizes a mesh may have. Statics on 50,000 tets take ~1.5 s, so a million is far beyond use
// yet still fits in memory; anything larger is refused before it is built.
namespace shapectl {

inline constexpr long max_mesh_tets = 1'000'000;
inline constexpr long max_mesh_nodes = 1'000'000;
inline constexpr long max_surface_triangles = 500'000;
// TetGen stops adding points here (its -S switch), so refinement cannot run without bound;
// a quality mesh has ~6 tets per point.
inline constexpr long max_tetgen_added_points = 150'000;
// A tet volume bound asking for more than this many tets of the enclosed volume is refused
// before TetGen runs: TetGen's tets come out several times smaller than the bound.
inline constexpr long max_tetgen_volume_ratio = 200'000;

}  // namespace shapectl

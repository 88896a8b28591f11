// A program outside the shapectl tree, built against an installed one (tests/install/):
// the statics of a scene at its reference joints, printed for comparison with the CLI's.
#include <cstdio>
#include <exception>

#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/sim/gripped_object.hpp>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer SCENE.json\n");
    return 1;
  }
  try {
    const shapectl::Scene scene = shapectl::load_scene(argv[1]);
    const shapectl::GrippedObject object(scene);
    const shapectl::ObjectState state =
        object.solve_from(object.reference_joints(), object.reference_positions());
    std::printf("nodes %d\nconverged %d\niterations %d\nenergy %.17g\n", object.node_count(),
                state.statics().converged() ? 1 : 0, state.statics().iterations,
                state.statics().energy);
    return state.statics().converged() ? 0 : 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

# scene_io/: SCENE.json → Scene, the strict scene reader. Above sim/: it loads the meshes and the
# URDF a scene names and runs sim/'s scene checks; sim/scene.hpp itself sees no JSON.
shapectl_area(scene_io)
target_link_libraries(shapectl_scene_io PUBLIC shapectl_sim
                      PRIVATE shapectl_contact shapectl_fem shapectl_io shapectl_linalg shapectl_mesh
                              shapectl_robot)

shapectl_tests(scene_io shapectl_scene_io)
if(TARGET scene_io_tests)
  add_dependencies(scene_io_tests shapectl_cli)  # they run the CLI
endif()

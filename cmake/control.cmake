# control/: objectives, optimizers, the continuous controller.
shapectl_area(control)
target_link_libraries(shapectl_control PUBLIC shapectl_io shapectl_mesh shapectl_robot shapectl_sim)

shapectl_tests(control shapectl_control shapectl_scene_io)  # the tests load scene files
if(TARGET control_tests AND NOT SHAPECTL_TSAN)  # the TSan tree runs no CLI
  add_dependencies(control_tests shapectl_cli)  # they run the CLI
endif()

# calib/: the real object — observations (tracked markers, point clouds), the parameters a
# calibration fits and their sensitivities, the calibration itself.
find_package(PNG REQUIRED)  # depth images (calib/depth_png.hpp)
shapectl_area(calib)
target_link_libraries(shapectl_calib PUBLIC shapectl_control shapectl_fem shapectl_io shapectl_link shapectl_mesh shapectl_robot shapectl_sim
                      PRIVATE shapectl_scene_io PNG::PNG)

shapectl_tests(calib shapectl_calib shapectl_scene_io)

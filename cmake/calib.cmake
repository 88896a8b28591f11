# calib/: observations of the real object (tracked markers, point clouds) and the geometry its
# calibration needs (closest points on the deformed surface).
shapectl_area(calib)
target_link_libraries(shapectl_calib PUBLIC shapectl_io shapectl_robot PRIVATE shapectl_mesh)

shapectl_tests(calib shapectl_calib shapectl_mesh)

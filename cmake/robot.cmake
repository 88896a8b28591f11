# robot/: RobotModel from URDF (urdfdom), kinematics, collision spheres.
find_package(PkgConfig REQUIRED)
pkg_check_modules(URDFDOM REQUIRED IMPORTED_TARGET urdfdom)
pkg_check_modules(TINYXML REQUIRED IMPORTED_TARGET tinyxml)  # the xacro expander

shapectl_area(robot)
target_link_libraries(shapectl_robot PUBLIC shapectl_io PRIVATE PkgConfig::URDFDOM PkgConfig::TINYXML)

shapectl_tests(robot shapectl_robot)

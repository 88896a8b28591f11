# robot/: RobotModel from URDF (urdfdom), kinematics, collision spheres.
find_package(PkgConfig REQUIRED)
pkg_check_modules(URDFDOM REQUIRED IMPORTED_TARGET urdfdom)

shapectl_area(robot)
target_link_libraries(shapectl_robot PUBLIC shapectl_io PRIVATE PkgConfig::URDFDOM)

shapectl_tests(robot shapectl_robot)

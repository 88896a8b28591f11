# `cmake --install build [--prefix P]`: what a C++ or Python user of shapectl needs.
#   include/shapectl/            the headers
#   lib/libshapectl_*.a          the area libraries
#   lib/cmake/shapectl/          find_package(shapectl) → shapectl::shapectl (all areas)
#   lib/pkgconfig/shapectl.pc    pkg-config --cflags --libs shapectl
#   bin/shapectl                 the CLI
#   share/shapectl/              web/ (the GUI, three.js included), scenes/, data/robots/
#   lib/python3.X/dist-packages/shapectl/   the Python package (SHAPECTL_PYTHON_INSTALL_DIR)
# Both package files are relocatable: the tree may be installed under any prefix or moved.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(shapectl_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/shapectl)
set(shapectl_data_dir ${CMAKE_INSTALL_DATADIR}/shapectl)

# The areas' headers come from src/ in the build tree and from include/ once installed.
foreach(area IN LISTS shapectl_areas)
  get_target_property(includes shapectl_${area} INTERFACE_INCLUDE_DIRECTORIES)
  list(REMOVE_ITEM includes ${PROJECT_SOURCE_DIR}/src)
  list(APPEND includes "$<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src>")
  set_target_properties(shapectl_${area} PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${includes}"
    EXPORT_NAME ${area})  # shapectl::io, shapectl::sim, …
endforeach()

install(DIRECTORY ${PROJECT_SOURCE_DIR}/src/shapectl DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.hpp")
# With SHAPECTL_NATIVE (OFF by default) -march=native travels with the targets (a PUBLIC compile
# option of every area): Eigen's fixed-size types change layout with it, so consumers must compile
# with it too. Without it, consumers are given no instruction-set flag (portable_install).
install(TARGETS shapectl ${area_libraries} EXPORT shapectl-targets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT shapectl-targets NAMESPACE shapectl:: DESTINATION ${shapectl_cmake_dir})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/shapectl-config.cmake.in
  ${PROJECT_BINARY_DIR}/shapectl-config.cmake INSTALL_DESTINATION ${shapectl_cmake_dir})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/shapectl-config-version.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/shapectl-config.cmake
              ${PROJECT_BINARY_DIR}/shapectl-config-version.cmake
        DESTINATION ${shapectl_cmake_dir})

# pkg-config: the libraries are static, so Libs names everything they link (dependents first:
# shapectl_areas is in dependency order), and Requires the packages that have .pc files.
set(pc_libs "")
foreach(area IN LISTS shapectl_areas)
  string(PREPEND pc_libs "-lshapectl_${area} ")
endforeach()
list(JOIN LAPACK_LIBRARIES " " pc_lapack)
list(JOIN BLAS_LIBRARIES " " pc_blas)
string(APPEND pc_libs "${TETGEN_LIB} ${CHOLMOD_LIB} ${AMD_LIB} ${pc_lapack} ${pc_blas} -pthread")
set(pc_cflags "")
if(SHAPECTL_NATIVE)
  set(pc_cflags "-march=native")
endif()
file(RELATIVE_PATH pc_prefix_from_pcfiledir "/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/")
configure_file(${PROJECT_SOURCE_DIR}/cmake/shapectl.pc.in ${PROJECT_BINARY_DIR}/shapectl.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/shapectl.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

install(TARGETS shapectl_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

# Data beside each other as in the source tree: scenes name ../data/robots/…; the bundled
# scenes' meshes are boxes (no mesh files).
install(DIRECTORY ${PROJECT_SOURCE_DIR}/scenes DESTINATION ${shapectl_data_dir})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/data/robots DESTINATION ${shapectl_data_dir}/data)

# The GUI: the page and its modules, and of three.js (npm ci in web/) what the page imports.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/web/ DESTINATION ${shapectl_data_dir}/web
        PATTERN node_modules EXCLUDE PATTERN "package*.json" EXCLUDE)
set(three ${PROJECT_SOURCE_DIR}/web/node_modules/three)
install(CODE "
  if(NOT EXISTS \"${three}/build/three.module.js\")
    message(FATAL_ERROR \"${three} is missing: run `npm ci` in web/ (scripts/setup.sh does)\")
  endif()")
install(FILES ${three}/LICENSE ${three}/package.json
        DESTINATION ${shapectl_data_dir}/web/node_modules/three)
install(FILES ${three}/build/three.module.js ${three}/build/three.core.js
        DESTINATION ${shapectl_data_dir}/web/node_modules/three/build)
install(FILES ${three}/examples/jsm/controls/OrbitControls.js
              ${three}/examples/jsm/controls/TransformControls.js
        DESTINATION ${shapectl_data_dir}/web/node_modules/three/examples/jsm/controls)
# Screen-width lines for centre-lines and sketches (web/js/screen_line.js).
install(FILES ${three}/examples/jsm/lines/Line2.js ${three}/examples/jsm/lines/LineGeometry.js
              ${three}/examples/jsm/lines/LineMaterial.js ${three}/examples/jsm/lines/LineSegments2.js
              ${three}/examples/jsm/lines/LineSegmentsGeometry.js
        DESTINATION ${shapectl_data_dir}/web/node_modules/three/examples/jsm/lines)
# The robot's mesh visuals (web/js/mesh_loader.js), with what ColladaLoader imports.
install(FILES ${three}/examples/jsm/loaders/STLLoader.js ${three}/examples/jsm/loaders/OBJLoader.js
              ${three}/examples/jsm/loaders/ColladaLoader.js ${three}/examples/jsm/loaders/TGALoader.js
        DESTINATION ${shapectl_data_dir}/web/node_modules/three/examples/jsm/loaders)
install(FILES ${three}/examples/jsm/loaders/collada/ColladaParser.js
              ${three}/examples/jsm/loaders/collada/ColladaComposer.js
        DESTINATION ${shapectl_data_dir}/web/node_modules/three/examples/jsm/loaders/collada)

install(FILES ${PROJECT_SOURCE_DIR}/LICENSE ${PROJECT_SOURCE_DIR}/README.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR})

# The Python package where Debian's python3 looks under the prefix (/usr/local by default).
set(python_install_dir "")
if(TARGET shapectl_python)
  set(SHAPECTL_PYTHON_INSTALL_DIR
      "lib/python${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}/dist-packages"
      CACHE STRING "Where `cmake --install` puts the Python package, relative to the prefix")
  install(TARGETS shapectl_python LIBRARY DESTINATION ${SHAPECTL_PYTHON_INSTALL_DIR}/shapectl)
  install(FILES ${python_package_files} DESTINATION ${SHAPECTL_PYTHON_INSTALL_DIR}/shapectl)
  set(python_install_dir ${SHAPECTL_PYTHON_INSTALL_DIR})
endif()

# An out-of-tree project builds against an installed tree (tests/install/).
if(SHAPECTL_BUILD_TESTS)
  add_test(NAME install_consumer
    COMMAND bash ${PROJECT_SOURCE_DIR}/tests/install/install_test.sh ${PROJECT_BINARY_DIR}
            "${pc_cflags}" "${python_install_dir}")
  set_tests_properties(install_consumer PROPERTIES TIMEOUT 600)
  if(NOT SHAPECTL_NATIVE)  # a native build runs only on CPUs like this one, by request
    add_test(NAME portable_install
      COMMAND bash ${PROJECT_SOURCE_DIR}/tests/install/portable_test.sh ${PROJECT_BINARY_DIR}
              "${python_install_dir}")
    set_tests_properties(portable_install PROPERTIES TIMEOUT 900)
  endif()
endif()

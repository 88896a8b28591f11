# python/: the `shapectl` Python module (pybind11 + numpy from Debian) and its pytest tests.
# Built into build/python/shapectl/ (the package: __init__.py, batch.py, stubs and the compiled
# _shapectl): `PYTHONPATH=build/python python3 -c "import shapectl"`; cmake/install.cmake
# installs it. docs/python.md is its guide.

# Debian's interpreter: pybind11-dev, python3-numpy and python3-pytest are installed for it, while
# the `python3` first on PATH may be another one (pyenv) without them.
if(NOT DEFINED Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python3_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "Python interpreter for the module")
endif()
set(PYBIND11_FINDPYTHON ON)
find_package(Python3 COMPONENTS Interpreter Development.Module QUIET)
find_package(pybind11 CONFIG QUIET)
if(Python3_FOUND AND pybind11_FOUND)
  set(shapectl_python_default ON)
else()
  set(shapectl_python_default OFF)
endif()
option(SHAPECTL_BUILD_PYTHON "Build the Python module (needs pybind11-dev, python3-dev)"
       ${shapectl_python_default})
if(NOT SHAPECTL_BUILD_PYTHON)
  return()
endif()
if(NOT pybind11_FOUND)
  message(FATAL_ERROR "SHAPECTL_BUILD_PYTHON is ON but pybind11 was not found (apt-get install pybind11-dev)")
endif()

# The module is a shared object: the area libraries it links must be position-independent.
foreach(area IN LISTS shapectl_areas)
  set_target_properties(shapectl_${area} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endforeach()

set(shapectl_python_dir ${PROJECT_BINARY_DIR}/python)
file(GLOB python_binding_sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/python/src/*.cpp)
# NO_EXTRAS: no LTO (a serial link of minutes; the solvers live in the area libraries anyway).
pybind11_add_module(shapectl_python MODULE NO_EXTRAS ${python_binding_sources})
set_target_properties(shapectl_python PROPERTIES
  OUTPUT_NAME _shapectl
  LIBRARY_OUTPUT_DIRECTORY ${shapectl_python_dir}/shapectl
  UNITY_BUILD ${SHAPECTL_UNITY_BUILD})
target_link_libraries(shapectl_python PRIVATE shapectl_calib shapectl_control shapectl_scene_io shapectl_sim shapectl_robot shapectl_runtime shapectl_io)
target_compile_options(shapectl_python PRIVATE -Wno-subobject-linkage)

# The pure-Python part of the package (and its stubs) beside the compiled module.
file(GLOB python_package_files CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/python/shapectl/*)
foreach(file IN LISTS python_package_files)
  get_filename_component(name ${file} NAME)
  configure_file(${file} ${shapectl_python_dir}/shapectl/${name} COPYONLY)
endforeach()

# pytest, as two CTest tests: the module (it runs the CLI to compare against it), and
# shapectl.batch with the examples in examples/python (they need python3-matplotlib,
# python3-dask and python3-distributed).
if(SHAPECTL_BUILD_TESTS)
  set(python_test_dir ${PROJECT_SOURCE_DIR}/tests/python)
  set(python_example_tests ${python_test_dir}/test_batch.py ${python_test_dir}/test_examples.py)
  list(TRANSFORM python_example_tests PREPEND "--ignore=" OUTPUT_VARIABLE python_ignores)
  add_test(NAME python_tests
    COMMAND ${Python3_EXECUTABLE} -m pytest -q -p no:cacheprovider ${python_test_dir} ${python_ignores})
  add_test(NAME python_examples
    COMMAND ${Python3_EXECUTABLE} -m pytest -q -p no:cacheprovider ${python_example_tests})
  set_tests_properties(python_tests python_examples PROPERTIES
    ENVIRONMENT "PYTHONPATH=${shapectl_python_dir};SHAPECTL_CLI=$<TARGET_FILE:shapectl_cli>;SHAPECTL_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
    TIMEOUT 600)
endif()

# cmake/OrbisDocs.cmake — the `docs` target: the API reference from the public headers.
#
# Doxygen over include/orbis and adapters/include/orbis (docs/api/Doxyfile.in), every warning an
# error (cmake/RunDoxygen.cmake); pydoc over the Python module when it is built. Without Doxygen
# (Debian `doxygen`, installed by scripts/install-deps) the target says so and fails.
find_program(ORBIS_DOXYGEN_EXECUTABLE doxygen)
set(ORBIS_DOCS_OUTPUT_DIR "${PROJECT_BINARY_DIR}/docs")
find_package(Python3 COMPONENTS Interpreter QUIET)
configure_file("${PROJECT_SOURCE_DIR}/docs/api/Doxyfile.in" "${ORBIS_DOCS_OUTPUT_DIR}/Doxyfile" @ONLY)
set(ORBIS_DOCS_COMMAND "${CMAKE_COMMAND}" "-DDOXYGEN=${ORBIS_DOXYGEN_EXECUTABLE}"
    "-DDOXYFILE=${ORBIS_DOCS_OUTPUT_DIR}/Doxyfile" "-DOUTPUT_DIR=${ORBIS_DOCS_OUTPUT_DIR}")
if(ORBIS_BUILD_PYTHON)
  list(APPEND ORBIS_DOCS_COMMAND "-DPYTHON=${Python3_EXECUTABLE}" "-DPYTHONPATH=${PROJECT_BINARY_DIR}/python")
endif()
list(APPEND ORBIS_DOCS_COMMAND -P "${PROJECT_SOURCE_DIR}/cmake/RunDoxygen.cmake")
if(ORBIS_DOXYGEN_EXECUTABLE)
  add_custom_target(docs COMMAND ${ORBIS_DOCS_COMMAND} VERBATIM
                    COMMENT "Building the API reference (Doxygen; any warning fails)")
  if(ORBIS_BUILD_PYTHON)
    add_dependencies(docs _orbis)
  endif()
else()
  add_custom_target(docs COMMAND ${CMAKE_COMMAND} -E echo "docs: doxygen not found (Debian: doxygen; scripts/install-deps)"
                    COMMAND ${CMAKE_COMMAND} -E false VERBATIM)
endif()
# The test suite builds the reference too, so an undocumented public symbol fails CI.
if(ORBIS_BUILD_TESTS AND ORBIS_DOXYGEN_EXECUTABLE)
  add_test(NAME api_reference COMMAND ${ORBIS_DOCS_COMMAND})
  set_tests_properties(api_reference PROPERTIES TIMEOUT 600)
endif()

# cmake/RunDoxygen.cmake — builds the API reference and fails on any Doxygen warning.
#
# cmake -DDOXYGEN=... -DDOXYFILE=... -DOUTPUT_DIR=... [-DPYTHON=... -DPYTHONPATH=...] -P RunDoxygen.cmake
# Doxygen writes its warnings (an undocumented public symbol, a broken reference, a malformed
# command) to OUTPUT_DIR/warnings.log; they are printed and the build fails when there is one.
# With PYTHON and PYTHONPATH (the built module), pydoc writes the Python reference from the
# module's docstrings into OUTPUT_DIR/python/.
file(MAKE_DIRECTORY "${OUTPUT_DIR}")
file(REMOVE "${OUTPUT_DIR}/warnings.log")
execute_process(COMMAND "${DOXYGEN}" "${DOXYFILE}" WORKING_DIRECTORY "${OUTPUT_DIR}"
                RESULT_VARIABLE status OUTPUT_QUIET ERROR_VARIABLE errors)
set(warnings "")
if(EXISTS "${OUTPUT_DIR}/warnings.log")
  file(READ "${OUTPUT_DIR}/warnings.log" warnings)
endif()
string(STRIP "${warnings}" warnings)
if(NOT status EQUAL 0 OR NOT warnings STREQUAL "")
  message(FATAL_ERROR "API reference: Doxygen reported problems (document the symbol in its header; "
                      "docs/api/README.md):\n${warnings}\n${errors}")
endif()
message(STATUS "API reference: ${OUTPUT_DIR}/html/index.html (no warnings)")
if(PYTHON AND PYTHONPATH)
  file(REMOVE_RECURSE "${OUTPUT_DIR}/python")
  file(MAKE_DIRECTORY "${OUTPUT_DIR}/python")
  execute_process(COMMAND "${CMAKE_COMMAND}" -E env "PYTHONPATH=${PYTHONPATH}"
                          "${PYTHON}" -m pydoc -w orbis orbis.datasets orbis.eval orbis.ba orbis._orbis
                  WORKING_DIRECTORY "${OUTPUT_DIR}/python" RESULT_VARIABLE pystatus OUTPUT_VARIABLE pyerrors ERROR_VARIABLE pyerrors)
  if(NOT pystatus EQUAL 0 OR NOT EXISTS "${OUTPUT_DIR}/python/orbis.html")
    message(FATAL_ERROR "Python reference: pydoc failed:\n${pyerrors}")
  endif()
  message(STATUS "Python reference: ${OUTPUT_DIR}/python/orbis.html")
endif()

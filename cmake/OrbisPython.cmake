# cmake/OrbisPython.cmake — finds the Python the orbis module is built and tested for.
#
# Sets Python3_* (FindPython3: Interpreter, Development.Module) and pybind11_FOUND. Without an
# explicit -DPython3_EXECUTABLE, the interpreter is the first of `python3` on PATH and
# /usr/bin/python3 that can import numpy: a shell's python3 may be a private build (pyenv) that
# lacks the Debian packages (python3-numpy, python3-pytest) the module's tests run on.
if(NOT Python3_EXECUTABLE)
  find_program(_orbis_path_python3 NAMES python3 NO_CACHE)
  foreach(candidate IN ITEMS "${_orbis_path_python3}" /usr/bin/python3)
    if(candidate AND EXISTS "${candidate}")
      execute_process(COMMAND "${candidate}" -c "import numpy" RESULT_VARIABLE _orbis_no_numpy
                      OUTPUT_QUIET ERROR_QUIET)
      if(_orbis_no_numpy EQUAL 0)
        set(Python3_EXECUTABLE "${candidate}" CACHE FILEPATH "Python interpreter of the orbis module")
        break()
      endif()
    endif()
  endforeach()
endif()
find_package(Python3 COMPONENTS Interpreter Development.Module QUIET)
if(Python3_FOUND)
  find_package(pybind11 CONFIG QUIET)
endif()

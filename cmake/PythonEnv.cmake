# A virtual environment under build/ with the pinned Python packages, made
# at configure time so that the FMI headers of the pinned fmpy are there
# before anything compiles: fmutrace/requirements.txt (the main job) always,
# tests/requirements.txt only for the tests (RL_TESTS).
find_package(Python3 3.11 REQUIRED COMPONENTS Interpreter)  # 3.11: tomllib

# RL_VENV_DIR lets a second build tree (the sanitizer build) share one venv.
set(RL_VENV_DIR ${CMAKE_BINARY_DIR}/venv CACHE PATH "Python virtual environment with the pinned packages")
set(VENV_DIR ${RL_VENV_DIR})
set(VENV_PYTHON ${VENV_DIR}/bin/python)
set(REQUIREMENTS ${CMAKE_SOURCE_DIR}/fmutrace/requirements.txt)
if(RL_TESTS)
  list(APPEND REQUIREMENTS ${CMAKE_SOURCE_DIR}/tests/requirements.txt)
endif()
# fmutrace's C extensions (the step loop, the reader of plain CSV rows)
set(FMUTRACE_C_SOURCES ${CMAKE_SOURCE_DIR}/fmutrace/src/fmutrace/_steps.c ${CMAKE_SOURCE_DIR}/fmutrace/src/fmutrace/_rows.c)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${REQUIREMENTS} ${CMAKE_SOURCE_DIR}/fmutrace/pyproject.toml
             ${FMUTRACE_C_SOURCES})

file(READ ${CMAKE_SOURCE_DIR}/fmutrace/pyproject.toml requirements_text)
# fmutrace's C extensions are compiled by its install: a changed source installs it again
foreach(file IN LISTS REQUIREMENTS FMUTRACE_C_SOURCES)
  file(READ ${file} text)
  string(APPEND requirements_text "${text}")
endforeach()
string(SHA256 requirements_hash "${requirements_text}")
set(venv_stamp ${VENV_DIR}/requirements-${requirements_hash}.stamp)

if(NOT EXISTS ${venv_stamp})
  if(NOT EXISTS ${VENV_PYTHON})
    message(STATUS "Creating ${VENV_DIR}")
    execute_process(COMMAND ${Python3_EXECUTABLE} -m venv ${VENV_DIR} RESULT_VARIABLE venv_failed)
    if(venv_failed)
      # Debian ships venv's pip bootstrap separately (python3-venv)
      file(REMOVE_RECURSE ${VENV_DIR})
      apt_install("python3 -m venv failed" python3-venv)
      execute_process(COMMAND ${Python3_EXECUTABLE} -m venv ${VENV_DIR} RESULT_VARIABLE venv_failed)
      if(venv_failed)
        message(FATAL_ERROR "Cannot create a Python virtual environment (on Debian: apt-get install python3-venv)")
      endif()
    endif()
  endif()
  set(pip_args)
  foreach(file IN LISTS REQUIREMENTS)
    list(APPEND pip_args -r ${file})
  endforeach()
  message(STATUS "Installing the pinned Python packages of ${REQUIREMENTS}")
  execute_process(COMMAND ${VENV_PYTHON} -m pip install --disable-pip-version-check -q ${pip_args}
                  RESULT_VARIABLE pip_failed)
  if(pip_failed)
    message(FATAL_ERROR "pip install ${pip_args} failed")
  endif()
  # the trace tool, editable: the venv runs the source tree's fmutrace; its
  # C extensions compile against the Python headers
  execute_process(COMMAND ${VENV_PYTHON} -c "import sysconfig; print(sysconfig.get_path('include'))"
                  OUTPUT_VARIABLE python_include OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT EXISTS ${python_include}/Python.h)
    apt_install("No Python headers for fmutrace's C extensions" python3-dev)
  endif()
  execute_process(COMMAND ${VENV_PYTHON} -m pip install --disable-pip-version-check -q --no-deps
                          --no-build-isolation -e ${CMAKE_SOURCE_DIR}/fmutrace
                  RESULT_VARIABLE pip_failed)
  if(pip_failed)
    message(FATAL_ERROR "pip install -e fmutrace failed")
  endif()
  # the extensions' build is optional (pip -q hides a failed compile): say so,
  # and leave the stamp unwritten so that the next configure tries again
  execute_process(COMMAND ${VENV_PYTHON} -c "import fmutrace._steps, fmutrace._rows" RESULT_VARIABLE c_failed
                  OUTPUT_QUIET ERROR_QUIET)
  file(GLOB old_stamps ${VENV_DIR}/requirements-*.stamp)
  if(old_stamps)
    file(REMOVE ${old_stamps})
  endif()
  if(c_failed)
    message(WARNING "fmutrace's C extensions (fmutrace/_steps.c, _rows.c) were not built: fmutrace steps in "
                    "Python, several times slower, and reads CSV rows with pyarrow only. They need a C compiler and the Python headers (on Debian: "
                    "apt-get install python3-dev); the next configure tries again.")
  else()
    file(TOUCH ${venv_stamp})
  endif()
endif()

execute_process(
  COMMAND ${VENV_PYTHON} -c "import fmpy, os; print(os.path.join(os.path.dirname(fmpy.__file__), 'c-code'))"
  OUTPUT_VARIABLE FMI_HEADERS_DIR OUTPUT_STRIP_TRAILING_WHITESPACE COMMAND_ERROR_IS_FATAL ANY)
if(NOT EXISTS ${FMI_HEADERS_DIR}/fmi2Functions.h OR NOT EXISTS ${FMI_HEADERS_DIR}/fmi3Functions.h)
  message(FATAL_ERROR "The FMI headers are not in ${FMI_HEADERS_DIR}")
endif()
message(STATUS "FMI headers: ${FMI_HEADERS_DIR}")

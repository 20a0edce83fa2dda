# A virtual environment under build/ with the pinned Python packages of
# tests/requirements.txt, made at configure time so that the FMI headers of
# the pinned fmpy are there before anything compiles.
find_package(Python3 3.11 REQUIRED COMPONENTS Interpreter)  # 3.11: tomllib

# RL_VENV_DIR lets a second build tree (the sanitizer build) share one venv.
set(RL_VENV_DIR ${CMAKE_BINARY_DIR}/venv CACHE PATH "Python virtual environment with the pinned packages")
set(VENV_DIR ${RL_VENV_DIR})
set(VENV_PYTHON ${VENV_DIR}/bin/python)
set(REQUIREMENTS ${CMAKE_SOURCE_DIR}/tests/requirements.txt)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${REQUIREMENTS})

file(SHA256 ${REQUIREMENTS} requirements_hash)
set(venv_stamp ${VENV_DIR}/requirements-${requirements_hash}.stamp)

if(NOT EXISTS ${venv_stamp})
  if(NOT EXISTS ${VENV_PYTHON})
    message(STATUS "Creating ${VENV_DIR}")
    execute_process(COMMAND ${Python3_EXECUTABLE} -m venv ${VENV_DIR} RESULT_VARIABLE venv_failed)
    if(venv_failed)
      # Debian ships venv's pip bootstrap separately (python3-venv)
      find_program(APT_GET apt-get)
      if(APT_GET)
        message(STATUS "python3 -m venv failed: installing Debian's python3-venv")
        execute_process(COMMAND sh -c "${APT_GET} update -qq && DEBIAN_FRONTEND=noninteractive ${APT_GET} install -y -qq python3-venv"
                        RESULT_VARIABLE apt_failed)
        file(REMOVE_RECURSE ${VENV_DIR})
        execute_process(COMMAND ${Python3_EXECUTABLE} -m venv ${VENV_DIR} RESULT_VARIABLE venv_failed)
      endif()
      if(venv_failed)
        message(FATAL_ERROR "Cannot create a Python virtual environment (on Debian: apt-get install python3-venv)")
      endif()
    endif()
  endif()
  message(STATUS "Installing the pinned Python packages of ${REQUIREMENTS}")
  execute_process(COMMAND ${VENV_PYTHON} -m pip install --disable-pip-version-check -q -r ${REQUIREMENTS}
                  RESULT_VARIABLE pip_failed)
  if(pip_failed)
    message(FATAL_ERROR "pip install -r ${REQUIREMENTS} failed")
  endif()
  file(GLOB old_stamps ${VENV_DIR}/requirements-*.stamp)
  if(old_stamps)
    file(REMOVE ${old_stamps})
  endif()
  file(TOUCH ${venv_stamp})
endif()

# ecospy's native library needs Debian's libtbb12 (and unzip for FMUs)
execute_process(COMMAND ${VENV_PYTHON} -c "import ecospy" RESULT_VARIABLE ecospy_failed OUTPUT_QUIET ERROR_QUIET)
find_program(UNZIP unzip)
if(ecospy_failed OR NOT UNZIP)
  apt_install("ecospy cannot load" libtbb12 unzip)
endif()

execute_process(
  COMMAND ${VENV_PYTHON} -c "import fmpy, os; print(os.path.join(os.path.dirname(fmpy.__file__), 'c-code'))"
  OUTPUT_VARIABLE FMI_HEADERS_DIR OUTPUT_STRIP_TRAILING_WHITESPACE COMMAND_ERROR_IS_FATAL ANY)
if(NOT EXISTS ${FMI_HEADERS_DIR}/fmi2Functions.h OR NOT EXISTS ${FMI_HEADERS_DIR}/fmi3Functions.h)
  message(FATAL_ERROR "The FMI headers are not in ${FMI_HEADERS_DIR}")
endif()
message(STATUS "FMI headers: ${FMI_HEADERS_DIR}")

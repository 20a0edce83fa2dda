# The tools the tests need and the product does not (RL_TESTS only, the
# test command): each installed here when missing, with what it is for.
# Debian's packages:
#   wine64                          the win64 binaries run under fmpy's remoting (test_windows)
#   default-jre-headless, maven     VDMCheck2, the FMI 2 validator (test_validators)
#   clang-14, libclang-rt-14-dev    libFuzzer with ASan/UBSan (ctest fuzz_*; cmake/Fuzz.cmake)
#   valgrind                        memcheck (ctest memcheck_*) and callgrind (benchmarks)
#   libtbb12, unzip                 ecospy, another importer (test_importers, test_closed_loop)
#   qemu-user                       the aarch64 binaries and harnesses under emulation (test_aarch64)
#   g++                             the sources compiled as C++ (test_source_fmu)
#   clang-format-14                 the C sources' layout (ctest lint, .pre-commit-config.yaml)
#   chromium, chromium-driver       the report's pages in a real browser (tests/fmutrace/test_report_browser.py)
# Python packages: tests/requirements.txt (cmake/PythonEnv.cmake).
# A tool that still cannot be had makes its tests fail and say why.

# wine64 (Debian keeps it in /usr/lib/wine)
find_program(WINE64 wine64 PATHS /usr/lib/wine NO_CACHE)
if(NOT WINE64)
  apt_install("No wine64 for the Windows test" wine64)
  find_program(WINE64 wine64 PATHS /usr/lib/wine NO_CACHE)
endif()
set(WINE_DIR "")
if(WINE64)
  get_filename_component(WINE_DIR ${WINE64} DIRECTORY)
endif()

# Java and Maven for VDMCheck2
find_program(JAVA java)
find_program(MAVEN mvn)
if(NOT JAVA OR NOT MAVEN)
  apt_install("VDMCheck2 needs Java and Maven" default-jre-headless maven)
  find_program(JAVA java)
  find_program(MAVEN mvn)
endif()
include(cmake/VDMCheck.cmake)

# valgrind
find_program(VALGRIND valgrind)
if(NOT VALGRIND)
  apt_install("No valgrind for the memcheck tests" valgrind)
  find_program(VALGRIND valgrind)
endif()

# qemu-user: the aarch64 Linux binaries run under emulation
find_program(QEMU_AARCH64 qemu-aarch64)
if(NOT QEMU_AARCH64)
  apt_install("No qemu-aarch64 for the aarch64 test" qemu-user)
  find_program(QEMU_AARCH64 qemu-aarch64)
endif()

# ecospy's native library needs libtbb12, and unzip for FMUs
execute_process(COMMAND ${VENV_PYTHON} -c "import ecospy" RESULT_VARIABLE ecospy_failed OUTPUT_QUIET ERROR_QUIET)
find_program(UNZIP unzip)
if(ecospy_failed OR NOT UNZIP)
  apt_install("ecospy cannot load" libtbb12 unzip)
endif()

# clang with libFuzzer: cmake/Fuzz.cmake

# a C++ compiler: the sources compile as C++ too (test_source_fmu)
find_program(CXX_COMPILER g++)
if(NOT CXX_COMPILER)
  apt_install("No g++ to compile the sources as C++" g++)
  find_program(CXX_COMPILER g++)
endif()

# clang-format, the lint stage's C layout check (.clang-format): Debian's,
# the version of the fuzzers' clang
find_program(CLANG_FORMAT NAMES clang-format-14 clang-format)
if(NOT CLANG_FORMAT)
  apt_install("No clang-format for the lint stage" clang-format-14)
  find_program(CLANG_FORMAT NAMES clang-format-14 clang-format)
endif()

# headless Chromium and its WebDriver: the report read in a browser, driven by selenium (tests/requirements.txt)
find_program(CHROMIUM chromium NO_CACHE)
find_program(CHROMEDRIVER chromedriver NO_CACHE)
if(NOT CHROMIUM OR NOT CHROMEDRIVER)
  apt_install("No Chromium for the report's browser tests" chromium chromium-driver)
endif()

# The standard's fmi2Functions.h, in build/fmi_headers, for the tests that
# link source FMUs into one binary (test_source_fmu): fmpy's copy names the
# functions without FMI2_FUNCTION_PREFIX, as its shared libraries need; the
# standard's prepends it (fmi2FullName). fmpy's fmi3Functions.h is the
# standard's and honours FMI3_FUNCTION_PREFIX as it is.
file(READ ${FMI_HEADERS_DIR}/fmi2Functions.h fmi2_functions)
set(fmpy_full_name "#define fmi2FullName(name) name\n")
string(FIND "${fmi2_functions}" "${fmpy_full_name}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "${FMI_HEADERS_DIR}/fmi2Functions.h: no '${fmpy_full_name}' to restore the standard's from")
endif()
string(REPLACE "${fmpy_full_name}" "#if defined(FMI2_FUNCTION_PREFIX)
  #define fmi2Paste(a,b)     a ## b
  #define fmi2PasteB(a,b)    fmi2Paste(a,b)
  #define fmi2FullName(name) fmi2PasteB(FMI2_FUNCTION_PREFIX, name)
#else
  #define fmi2FullName(name) name
#endif
" fmi2_functions "${fmi2_functions}")
set(STANDARD_FMI_HEADERS_DIR ${CMAKE_BINARY_DIR}/fmi_headers)
file(CONFIGURE OUTPUT ${STANDARD_FMI_HEADERS_DIR}/fmi2Functions.h CONTENT "${fmi2_functions}" @ONLY)

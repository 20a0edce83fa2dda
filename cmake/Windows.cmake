# Windows x86_64 FMU binaries (FMI 2 binaries/win64, FMI 3
# binaries/x86_64-windows), cross-compiled by the sub-build in
# cmake/windows with Debian's mingw-w64 (installed when missing: the FMUs
# carry these binaries). Sets WINDOWS_BUILD_DIR, or leaves it empty when no
# cross compiler is there.
include(ExternalProject)

set(WINDOWS_BUILD_DIR "")
find_program(MINGW_GCC x86_64-w64-mingw32-gcc)
if(NOT MINGW_GCC)
  apt_install("No mingw-w64 for the Windows binaries" gcc-mingw-w64-x86-64)
  find_program(MINGW_GCC x86_64-w64-mingw32-gcc)
endif()

if(MINGW_GCC)
  set(WINDOWS_BUILD_DIR ${CMAKE_BINARY_DIR}/windows)
  set(byproducts)
  foreach(model IN LISTS MODELS)
    list(APPEND byproducts ${WINDOWS_BUILD_DIR}/fmi2/${model}.dll ${WINDOWS_BUILD_DIR}/fmi3/${model}.dll)
  endforeach()
  list(JOIN MODELS "$<SEMICOLON>" models_arg)
  ExternalProject_Add(windows_binaries
    SOURCE_DIR ${CMAKE_SOURCE_DIR}/cmake/windows
    BINARY_DIR ${WINDOWS_BUILD_DIR}
    CMAKE_ARGS -DCMAKE_TOOLCHAIN_FILE=${CMAKE_SOURCE_DIR}/cmake/mingw-w64.cmake
               -DRL_SOURCE_DIR=${CMAKE_SOURCE_DIR} -DRL_GEN_DIR=${CMAKE_BINARY_DIR}/gen
               -DFMI_HEADERS_DIR=${FMI_HEADERS_DIR} -DMODELS=${models_arg}
    BUILD_ALWAYS ON
    INSTALL_COMMAND ""
    BUILD_BYPRODUCTS ${byproducts})
else()
  message(WARNING "No x86_64-w64-mingw32-gcc: the FMUs carry no Windows binaries")
endif()

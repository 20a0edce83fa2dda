# FMU binaries for other platforms, cross-compiled by sub-builds of
# cmake/cross with Debian's cross compilers (installed when missing: the FMUs
# carry these binaries):
#   windows  x86_64, mingw-w64: FMI 2 binaries/win64, FMI 3 binaries/x86_64-windows
#   aarch64  Linux, gcc-aarch64-linux-gnu: FMI 3 binaries/aarch64-linux
# Sets CROSS_BUILDS (the names built) and per name CROSS_<name>_DIR (the
# sub-build's folder), _SUFFIX (.dll, .so) and _PLATFORM2/_PLATFORM3 (the
# FMU's binaries folder per FMI version, empty: none). A platform whose
# compiler cannot be had is left out with a warning.
include(ExternalProject)

set(CROSS_BUILDS)

# add_cross_build(name compiler packages runtime toolchain platform suffix platform2 platform3):
# runtime, a file of the target's C library that must be there too
function(add_cross_build name compiler packages runtime toolchain platform suffix platform2 platform3)
  find_program(CROSS_${name}_CC ${compiler})
  if(NOT CROSS_${name}_CC OR NOT EXISTS ${runtime})
    apt_install("No ${compiler} or ${runtime} for the ${name} binaries" ${packages})
    find_program(CROSS_${name}_CC ${compiler})
  endif()
  if(NOT CROSS_${name}_CC OR NOT EXISTS ${runtime})
    message(WARNING "No ${compiler}: the FMUs carry no ${name} binaries")
    return()
  endif()
  set(dir ${CMAKE_BINARY_DIR}/${name})
  set(versions)
  set(byproducts)
  foreach(version 2 3)
    if(platform${version})
      list(APPEND versions ${version})
      foreach(model IN LISTS MODELS)
        list(APPEND byproducts ${dir}/fmi${version}/${model}${suffix})
      endforeach()
    endif()
  endforeach()
  list(JOIN MODELS "$<SEMICOLON>" models_arg)
  list(JOIN versions "$<SEMICOLON>" versions_arg)
  ExternalProject_Add(${name}_binaries
    SOURCE_DIR ${CMAKE_SOURCE_DIR}/cmake/cross
    BINARY_DIR ${dir}
    CMAKE_ARGS -DCMAKE_TOOLCHAIN_FILE=${CMAKE_SOURCE_DIR}/cmake/${toolchain}
               -DRL_SOURCE_DIR=${CMAKE_SOURCE_DIR} -DRL_GEN_DIR=${CMAKE_BINARY_DIR}/gen
               -DFMI_HEADERS_DIR=${FMI_HEADERS_DIR} -DMODELS=${models_arg} -DRL_VERSIONS=${versions_arg}
               -DRL_PLATFORM=${platform} -DRL_HARNESS=${RL_TESTS}
    BUILD_ALWAYS ON
    INSTALL_COMMAND ""
    BUILD_BYPRODUCTS ${byproducts})
  set(CROSS_${name}_DIR ${dir} PARENT_SCOPE)
  set(CROSS_${name}_SUFFIX ${suffix} PARENT_SCOPE)
  set(CROSS_${name}_PLATFORM2 ${platform2} PARENT_SCOPE)
  set(CROSS_${name}_PLATFORM3 ${platform3} PARENT_SCOPE)
  set(CROSS_BUILDS ${CROSS_BUILDS} ${name} PARENT_SCOPE)
endfunction()

add_cross_build(windows x86_64-w64-mingw32-gcc "gcc-mingw-w64-x86-64" /usr/x86_64-w64-mingw32/lib/libkernel32.a
                mingw-w64.cmake windows .dll win64 x86_64-windows)
add_cross_build(aarch64 aarch64-linux-gnu-gcc "gcc-aarch64-linux-gnu;libc6-dev-arm64-cross"
                /usr/aarch64-linux-gnu/lib/crti.o aarch64-linux-gnu.cmake linux .so "" aarch64-linux)

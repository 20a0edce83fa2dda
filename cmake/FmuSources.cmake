# The C sources of a model's FMU, relative to the source tree, written once
# for every build that compiles them (cmake/Fmu.cmake, cmake/Fuzz.cmake,
# the cross builds of cmake/cross):
#   fmu_sources(<var> <Model> <2|3>): the kernel, the core, the FMI glue
#   of that version and the model's mapping
#   FMU_HEADERS: the headers they include (the source FMU carries them)
set(FMU_HEADERS fmu_src/rate_limiter.h fmu_src/rate_limiter_rules.h fmu_src/model.h fmu_src/fmu_core.h
                fmu_src/models/siemens.h fmu_src/models/unified.h)

function(fmu_sources out model version)
  set(${out} fmu_src/rate_limiter.c fmu_src/fmu_core.c fmu_src/fmi${version}_glue.c fmu_src/models/${model}.c
      PARENT_SCOPE)
endfunction()

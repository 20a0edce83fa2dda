# Coverage-guided fuzzers (libFuzzer, with ASan and UBSan): tests/fuzz/*.c
# on the FMI 2 and FMI 3 glue of every model. libFuzzer comes with clang;
# when no clang here can build a fuzzer, Debian's clang-14 and
# libclang-rt-14-dev are installed with apt-get (as the CI machine needs).
# Without them the ctest test 'fuzz' fails and says why: no silent skip.

set(FUZZ_PROBE ${CMAKE_BINARY_DIR}/fuzz/probe.c)
file(WRITE ${FUZZ_PROBE} "#include <stddef.h>\n#include <stdint.h>\nint LLVMFuzzerTestOneInput(const uint8_t *d, size_t n);\nint LLVMFuzzerTestOneInput(const uint8_t *d, size_t n) { (void)d; (void)n; return 0; }\n")

function(find_fuzzing_clang out)
  find_program(clang_found NAMES clang-14 clang NO_CACHE)
  if(clang_found)
    execute_process(COMMAND ${clang_found} -fsanitize=fuzzer,address,undefined ${FUZZ_PROBE}
                            -o ${CMAKE_BINARY_DIR}/fuzz/probe
                    RESULT_VARIABLE failed OUTPUT_QUIET ERROR_QUIET)
    if(NOT failed)
      set(${out} ${clang_found} PARENT_SCOPE)
      return()
    endif()
  endif()
  set(${out} "" PARENT_SCOPE)
endfunction()

find_fuzzing_clang(FUZZ_CLANG)
if(NOT FUZZ_CLANG)
  apt_install("No clang with libFuzzer" clang-14 libclang-rt-14-dev)
  find_fuzzing_clang(FUZZ_CLANG)
endif()

set(FUZZ_TARGETS deserialize calls)
# fixed budget per target and model: 30 s with a fixed seed; inputs up to a
# few serialized states long (deserialize: one state of the largest model,
# RateLimiter's 705 bytes with its first byte, and some)
set(FUZZ_SECONDS 30)
set(FUZZ_MAX_LEN_deserialize 800)
set(FUZZ_MAX_LEN_calls 1024)
if(FUZZ_CLANG)
  message(STATUS "Fuzzers built with ${FUZZ_CLANG}")
  set(fuzz_binaries)
  set(fuzz_descriptions)
  foreach(model IN LISTS MODELS)
    set(suffix "_${model}")
    list(APPEND fuzz_descriptions ${model}_description)
    # both versions' sources: a fuzzer drives both glues
    fmu_sources(fmi2_sources ${model} 2)
    fmu_sources(fmi3_sources ${model} 3)
    set(fuzz_sources ${fmi2_sources} ${fmi3_sources})
    list(REMOVE_DUPLICATES fuzz_sources)
    list(TRANSFORM fuzz_sources PREPEND ${CMAKE_SOURCE_DIR}/)
    set(fuzz_headers ${FMU_HEADERS})
    list(TRANSFORM fuzz_headers PREPEND ${CMAKE_SOURCE_DIR}/)
    foreach(target IN LISTS FUZZ_TARGETS)
      set(binary ${CMAKE_BINARY_DIR}/fuzz/fuzz_${target}${suffix})
      add_custom_command(
        OUTPUT ${binary}
        COMMAND ${FUZZ_CLANG} -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all
                -ffp-contract=off -I${CMAKE_SOURCE_DIR}/fmu_src -I${CMAKE_BINARY_DIR}/gen/${model}
                -DMODEL_VARIABLES=${model}_variables.h
                -I${FMI_HEADERS_DIR} ${CMAKE_SOURCE_DIR}/tests/fuzz/fuzz_${target}.c ${fuzz_sources} -lm -o ${binary}
        DEPENDS ${CMAKE_SOURCE_DIR}/tests/fuzz/fuzz_${target}.c ${fuzz_sources} ${fuzz_headers}
                ${CMAKE_BINARY_DIR}/gen/${model}/${model}_variables.h
        COMMENT "Building the fuzzer fuzz_${target}${suffix}")
      list(APPEND fuzz_binaries ${binary})
      # new inputs go to build/fuzz/corpus_<target><suffix>; the repository's corpus is read
      add_test(NAME fuzz_${target}${suffix}
               COMMAND sh -c "mkdir -p '${CMAKE_BINARY_DIR}/fuzz/corpus_${target}${suffix}' && '${binary}' -max_total_time=${FUZZ_SECONDS} -max_len=${FUZZ_MAX_LEN_${target}} -seed=1 -print_final_stats=1 '${CMAKE_BINARY_DIR}/fuzz/corpus_${target}${suffix}' '${CMAKE_SOURCE_DIR}/tests/fuzz/corpus/${target}'")
      set_tests_properties(fuzz_${target}${suffix} PROPERTIES TIMEOUT 300 LABELS fuzz)
    endforeach()
  endforeach()
  # fmutrace's reader of plain CSV rows, against strtod (no model: built once)
  set(binary ${CMAKE_BINARY_DIR}/fuzz/fuzz_rows)
  set(rows_source ${CMAKE_SOURCE_DIR}/fmutrace/src/fmutrace/_rows.c)
  add_custom_command(
    OUTPUT ${binary}
    COMMAND ${FUZZ_CLANG} -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -ffp-contract=off
            -I${CMAKE_SOURCE_DIR}/fmutrace/src/fmutrace ${CMAKE_SOURCE_DIR}/tests/fuzz/fuzz_rows.c -o ${binary}
    DEPENDS ${CMAKE_SOURCE_DIR}/tests/fuzz/fuzz_rows.c ${rows_source}
    COMMENT "Building the fuzzer fuzz_rows")
  list(APPEND fuzz_binaries ${binary})
  add_test(NAME fuzz_rows
           COMMAND sh -c "mkdir -p '${CMAKE_BINARY_DIR}/fuzz/corpus_rows' && '${binary}' -max_total_time=${FUZZ_SECONDS} -max_len=256 -seed=1 -print_final_stats=1 '${CMAKE_BINARY_DIR}/fuzz/corpus_rows' '${CMAKE_SOURCE_DIR}/tests/fuzz/corpus/rows'")
  set_tests_properties(fuzz_rows PROPERTIES TIMEOUT 300 LABELS fuzz)
  add_custom_target(fuzzers ALL DEPENDS ${fuzz_binaries})
  add_dependencies(fuzzers ${fuzz_descriptions})
else()
  add_test(NAME fuzz COMMAND sh -c "echo 'no clang with libFuzzer (Debian: apt-get install clang-14 libclang-rt-14-dev)'; exit 1")
  set_tests_properties(fuzz PROPERTIES LABELS fuzz)
endif()

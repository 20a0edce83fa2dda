# add_fmu(<Model> <2|3>): build/fmi<2|3>/<Model>.fmu from the model's TOML
# file and its sources (cmake/FmuSources.cmake).
# The .fmu is a zip made by CMake alone, with fixed time stamps; the host
# tool zip_normalize (cmake/zip_normalize.c) then fixes what libarchive takes
# from the file system (access/change times, owner, umask), so that the same
# sources give the same bytes on any machine and for any user.
# A fixture passes its own TOML, C sources (relative to the source tree) and
# output folder: add_fmu(<Model> <2|3> TOML t SOURCES a.c ... OUTPUT_DIR d).
# add_fmu(<Model> 3 SCHEDULED_EXECUTION), after add_fmu(<Model> 3): build/fmi3-se/<Model>.fmu, FMI 3
# Scheduled Execution alone (with its Clock) on the same binary; build/fmi3/<Model>.fmu carries
# Co-Simulation and Model Exchange without a Clock (FMI 3.0, 4.4; docs/fmi.md, Scheduled Execution).

include(${CMAKE_CURRENT_LIST_DIR}/FmuSources.cmake)

add_custom_target(fmus ALL)

set(FMU_ZIP_MTIME "2000-01-01 00:00:00 UTC")
set(GENERATOR ${CMAKE_SOURCE_DIR}/modelDescription/generate.py)
set(FMI3_SE_FOLDER fmi3-se)  # generate.py's FMI3_VARIANTS names the same

function(add_fmu model version)
  cmake_parse_arguments(PARSE_ARGV 2 ARG "SCHEDULED_EXECUTION" "TOML;OUTPUT_DIR" "SOURCES")
  # the folder of this FMU's model description, stage and package; its binary is fmi<version>'s
  set(folder fmi${version})
  if(ARG_SCHEDULED_EXECUTION)
    set(folder ${FMI3_SE_FOLDER})
  endif()
  if(NOT TARGET zip_normalize)
    add_executable(zip_normalize ${CMAKE_SOURCE_DIR}/cmake/zip_normalize.c)
  endif()
  set(gen ${CMAKE_BINARY_DIR}/gen/${model})
  set(stage ${CMAKE_BINARY_DIR}/stage/${folder}/${model})
  set(toml ${CMAKE_SOURCE_DIR}/modelDescription/${model}.toml)
  set(header ${gen}/${model}_variables.h)
  # a product model compiles its unit, which includes its sources; a fixture its own sources
  if(ARG_TOML)
    set(toml ${CMAKE_SOURCE_DIR}/${ARG_TOML})
    set(sources ${ARG_SOURCES})
    set(unit)
    set(compiled ${sources})
    list(FILTER compiled INCLUDE REGEX "\\.c$")
    set(include_dirs fmu_src)
    set(out_dir ${ARG_OUTPUT_DIR})
  else()
    fmu_sources(sources ${model} ${version})
    list(APPEND sources ${FMU_HEADERS})
    fmu_unit(unit ${model} ${version} ${gen}/fmi${version})
    set(compiled ${unit})
    set(include_dirs ${FMU_INCLUDE_DIRS})
    set(out_dir ${CMAKE_BINARY_DIR}/${folder})
  endif()
  # what the model description lists (FMI 2 SourceFiles, FMI 3 buildDescription.xml)
  set(c_names)
  foreach(s IN LISTS compiled)
    get_filename_component(n ${s} NAME)
    list(APPEND c_names ${n})
  endforeach()
  if(version EQUAL 2)
    set(platform linux64)
  else()
    set(platform x86_64-linux)
  endif()

  # one generator run per model makes both versions' files (their source
  # lists differ only in the version named)
  if(NOT TARGET ${model}_description)
    string(REPLACE "fmi${version}" "fmi2" c_names2 "${c_names}")
    string(REPLACE "fmi${version}" "fmi3" c_names3 "${c_names}")
    add_custom_command(
      OUTPUT ${gen}/fmi2/modelDescription.xml ${gen}/fmi3/modelDescription.xml
             ${gen}/${FMI3_SE_FOLDER}/modelDescription.xml
             ${gen}/fmi3/buildDescription.xml ${header}
      COMMAND ${Python3_EXECUTABLE} ${GENERATOR} ${toml} ${gen}
              --fmi2-sources ${c_names2} --fmi3-sources ${c_names3}
      DEPENDS ${toml} ${GENERATOR} ${CMAKE_SOURCE_DIR}/LICENSE
      COMMENT "Generating the model descriptions of ${model}")
    add_custom_target(${model}_description DEPENDS ${header})
  endif()

  set(lib ${model}_fmi${version})
  set(copies)
  if(ARG_SCHEDULED_EXECUTION)
    # the same binary, built by add_fmu(<Model> 3)
    list(APPEND copies
      COMMAND ${CMAKE_COMMAND} -E make_directory ${stage}/binaries/${platform}
      COMMAND ${CMAKE_COMMAND} -E copy $<TARGET_FILE:${lib}> ${stage}/binaries/${platform}/)
  else()
    add_library(${lib} SHARED ${compiled} ${header})
    add_dependencies(${lib} ${model}_description)
    list(TRANSFORM include_dirs PREPEND ${CMAKE_SOURCE_DIR}/)
    target_include_directories(${lib} PRIVATE ${include_dirs} ${gen} ${FMI_HEADERS_DIR})
    target_link_libraries(${lib} PRIVATE m)
    target_link_options(${lib} PRIVATE -Wl,-z,defs)
    set_target_properties(${lib} PROPERTIES
      OUTPUT_NAME ${model} PREFIX ""
      LIBRARY_OUTPUT_DIRECTORY ${stage}/binaries/${platform})
  endif()

  list(TRANSFORM sources PREPEND ${CMAKE_SOURCE_DIR}/ REGEX "^[^/]")
  list(APPEND copies
    COMMAND ${CMAKE_COMMAND} -E make_directory ${stage}/sources
    COMMAND ${CMAKE_COMMAND} -E copy ${gen}/${folder}/modelDescription.xml ${stage}/
    COMMAND ${CMAKE_COMMAND} -E copy ${sources} ${unit} ${header} ${stage}/sources/
    # the licence, where the FMI 3 standard puts its entry point (FMI 2 names no place; the same there)
    COMMAND ${CMAKE_COMMAND} -E make_directory ${stage}/documentation/licenses
    COMMAND ${CMAKE_COMMAND} -E copy ${CMAKE_SOURCE_DIR}/LICENSE ${stage}/documentation/licenses/license.txt)
  set(entries modelDescription.xml binaries/${platform}/${model}.so documentation/licenses/license.txt)
  foreach(s IN LISTS sources unit header)
    get_filename_component(n ${s} NAME)
    list(APPEND entries sources/${n})
  endforeach()
  if(version EQUAL 3)
    list(APPEND copies COMMAND ${CMAKE_COMMAND} -E copy ${gen}/fmi3/buildDescription.xml ${stage}/sources/)
    list(APPEND entries sources/buildDescription.xml)
  endif()

  # the product models carry their documentation and icon, made from the
  # TOML file and a simulation of the staged FMU
  set(docs)
  if(NOT ARG_TOML)
    if(version EQUAL 2)
      set(icon model.png)
    else()
      set(icon terminalsAndIcons/icon.png)
    endif()
    set(doc_files documentation/index.html documentation/fmi-ls-ref.html documentation/ramp.png ${icon})
    list(TRANSFORM doc_files PREPEND ${stage}/ OUTPUT_VARIABLE docs)
    add_custom_command(
      OUTPUT ${docs}
      ${copies}
      COMMAND ${RUN_FMU_TOOL} ${VENV_PYTHON} ${CMAKE_SOURCE_DIR}/modelDescription/document.py
              ${toml} ${stage} ${version} ${CMAKE_SOURCE_DIR}/fmu_src/rate_limiter.c
              # the ramp is drawn by Co-Simulation, which the Scheduled Execution FMU does not declare
              ${CMAKE_BINARY_DIR}/stage/fmi${version}/${model}
      DEPENDS ${lib} ${toml} ${CMAKE_SOURCE_DIR}/modelDescription/document.py ${CMAKE_SOURCE_DIR}/fmu_src/rate_limiter.c
              ${CMAKE_SOURCE_DIR}/fmu_src/rate_limiter.h ${gen}/${folder}/modelDescription.xml
              ${gen}/${folder}/entries_ls_ref.txt  # (its page lists the experiments: references.py below)
      COMMENT "Documenting ${folder}/${model}")
    list(APPEND entries ${doc_files})
  endif()

  # the product models also carry the binaries of other platforms (cmake/CrossBuilds.cmake)
  set(cross_libraries)
  set(cross_targets)
  if(NOT ARG_TOML)
    foreach(name IN LISTS CROSS_BUILDS)
      set(cross_platform ${CROSS_${name}_PLATFORM${version}})
      if(cross_platform)
        set(cross_library ${CROSS_${name}_DIR}/fmi${version}/${model}${CROSS_${name}_SUFFIX})
        list(APPEND copies
          COMMAND ${CMAKE_COMMAND} -E make_directory ${stage}/binaries/${cross_platform}
          COMMAND ${CMAKE_COMMAND} -E copy ${cross_library} ${stage}/binaries/${cross_platform}/)
        list(APPEND entries binaries/${cross_platform}/${model}${CROSS_${name}_SUFFIX})
        list(APPEND cross_libraries ${cross_library})
        list(APPEND cross_targets ${name}_binaries)
      endif()
    endforeach()
  endif()
  list(SORT entries)

  # the product models carry their reference scenarios as FMI-LS-REF experiments
  # (modelDescription/references.py): the zip's entries are then its list
  set(zip_entries -- ${entries})
  set(references)
  if(NOT ARG_TOML)
    set(scenarios_dir ${CMAKE_SOURCE_DIR}/tests/scenarios/${model})
    file(GLOB_RECURSE scenario_files CONFIGURE_DEPENDS ${scenarios_dir}/*)
    list(JOIN entries "\n" entry_lines)
    file(CONFIGURE OUTPUT ${gen}/${folder}/entries.txt CONTENT "${entry_lines}\n" @ONLY)
    set(references ${gen}/${folder}/entries_ls_ref.txt)
    # the state after the first half of the first scenario, from the staged FMU (state.py); none in the
    # Scheduled Execution FMU, whose instances refuse a Co-Simulation state (docs/fmi.md)
    set(state)
    if(NOT ARG_SCHEDULED_EXECUTION)
      set(state ${gen}/fmi${version}/first_half.fmustate)
      add_custom_command(
        OUTPUT ${state}
        COMMAND ${CMAKE_COMMAND} -E copy ${gen}/fmi${version}/modelDescription.xml ${stage}/
        COMMAND ${RUN_FMU_TOOL} ${VENV_PYTHON} ${CMAKE_SOURCE_DIR}/modelDescription/state.py ${stage} ${version}
                ${scenarios_dir} ${state}
        DEPENDS ${lib} ${CMAKE_SOURCE_DIR}/modelDescription/state.py ${CMAKE_SOURCE_DIR}/modelDescription/references.py
                ${gen}/fmi${version}/modelDescription.xml ${scenario_files}
        COMMENT "Serializing a state of fmi${version}/${model}")
    endif()
    add_custom_command(
      OUTPUT ${references}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${stage}
      COMMAND ${CMAKE_COMMAND} -E copy ${gen}/${folder}/modelDescription.xml ${stage}/
      COMMAND ${Python3_EXECUTABLE} ${CMAKE_SOURCE_DIR}/modelDescription/references.py ${toml} ${scenarios_dir}
              ${stage} ${gen}/${folder}/entries.txt ${references} ${state}
      DEPENDS ${CMAKE_SOURCE_DIR}/modelDescription/references.py ${toml} ${scenario_files}
              ${gen}/${folder}/entries.txt ${state} ${gen}/${folder}/modelDescription.xml
      COMMENT "Writing the reference experiments of ${folder}/${model}")
    set(zip_entries --files-from=${references})
  endif()

  set(fmu ${out_dir}/${model}.fmu)
  add_custom_command(
    OUTPUT ${fmu}
    ${copies}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${out_dir}
    COMMAND ${CMAKE_COMMAND} -E tar cf ${fmu} --format=zip "--mtime=${FMU_ZIP_MTIME}" ${zip_entries}
    COMMAND zip_normalize ${fmu}
    WORKING_DIRECTORY ${stage}
    DEPENDS zip_normalize ${lib} ${sources} ${unit} ${header} ${gen}/${folder}/modelDescription.xml ${docs}
            ${CMAKE_SOURCE_DIR}/LICENSE ${references}
            ${cross_libraries}
    COMMENT "Packaging ${folder}/${model}.fmu")
  string(MAKE_C_IDENTIFIER ${model}_${folder}_fmu fmu_target)
  add_custom_target(${fmu_target} DEPENDS ${fmu})
  foreach(target IN LISTS cross_targets)
    add_dependencies(${fmu_target} ${target})
  endforeach()
  if(ARG_SCHEDULED_EXECUTION)
    add_dependencies(${fmu_target} ${model}_fmi3_fmu)  # its binary and its plot are fmi3's
  endif()
  add_dependencies(fmus ${fmu_target})
endfunction()

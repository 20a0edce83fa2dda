# VDMCheck2 1.1.3 (FMI 2 static checker, org.into-cps.vdmcheck): its jars
# fetched by Maven from its default repository, pinned by SHA-1, laid out as
# its launcher expects (the jars by short name beside vdmcheck2.jar, the VDM
# models and the schema unpacked). Sets VDMCHECK_JAR.
set(VDMCHECK_DIR ${CMAKE_BINARY_DIR}/vdmcheck)
set(VDMCHECK_JAR ${VDMCHECK_DIR}/vdmcheck2.jar)
set(MAVEN_DEPENDENCY_PLUGIN org.apache.maven.plugins:maven-dependency-plugin:3.8.1)
# short name | groupId:artifactId:version | SHA-1
set(vdmcheck_jars
  "vdmcheck2|org.into-cps.vdmcheck.fmi2:vdmcheck2:1.1.3|feae176bb0de1ca9ebd7a21dc433fca7c360c56a"
  "static-model|org.into-cps.vdmcheck.fmi2:static-model:1.1.3|d9ac4bcc6947fc0f76fe82838085d3e104742178"
  "rule-model|org.into-cps.vdmcheck.fmi2:rule-model:1.1.3|6d168dc1680f7ed65d98c998fb634079da77dcfc"
  "xsd2vdm|org.into-cps.vdmcheck:xsd2vdm:1.1.3|dc232db8f639629104b3bd5c6092b204f09bca1b"
  "fmuReader|org.into-cps.vdmcheck:fmuReader:1.1.3|d468c18abffdcb782f31eda66fae03499fbb6ec4"
  "vdmj|dk.au.ece.vdmj:vdmj:4.5.0|5e12c40ea36eb23b8b3b64f2655846b268117350"
  "annotations|dk.au.ece.vdmj:annotations:4.5.0|44d505bf4564b4a5e2733e084f5d261d3828e572")

if(MAVEN AND NOT EXISTS ${VDMCHECK_DIR}/ready.stamp)
  set(complete TRUE)
  foreach(entry IN LISTS vdmcheck_jars)
    string(REPLACE "|" ";" parts "${entry}")
    list(GET parts 0 short)
    list(GET parts 1 coordinates)
    list(GET parts 2 sha1)
    string(REPLACE ":" ";" gav "${coordinates}")
    list(GET gav 1 artifact)
    execute_process(COMMAND ${MAVEN} -q -B ${MAVEN_DEPENDENCY_PLUGIN}:copy -Dartifact=${coordinates}
                            -DoutputDirectory=${VDMCHECK_DIR}/download -Dmdep.stripVersion=true
                    RESULT_VARIABLE failed OUTPUT_QUIET)
    set(jar ${VDMCHECK_DIR}/download/${artifact}.jar)
    if(NOT failed AND EXISTS ${jar})
      file(SHA1 ${jar} actual)
    else()
      set(actual "")
    endif()
    if(actual STREQUAL sha1)
      file(COPY_FILE ${jar} ${VDMCHECK_DIR}/${short}.jar)
    else()
      message(WARNING "VDMCheck2: ${coordinates} could not be fetched or has SHA-1 '${actual}', not ${sha1}")
      set(complete FALSE)
    endif()
  endforeach()
  if(complete)
    # the launcher reads these folders beside its jar
    foreach(pair "static-model;fmi2-static-model" "rule-model;fmi2-rule-model" "vdmcheck2;fmi2schema")
      list(GET pair 0 jar)
      list(GET pair 1 folder)
      file(ARCHIVE_EXTRACT INPUT ${VDMCHECK_DIR}/${jar}.jar DESTINATION ${VDMCHECK_DIR} PATTERNS ${folder})
    endforeach()
    file(TOUCH ${VDMCHECK_DIR}/ready.stamp)
  endif()
endif()

# VDMCheck2 1.1.3 (FMI 2 static checker, org.into-cps.vdmcheck on Maven
# Central): its jars, pinned by SHA-1, laid out as its launcher expects
# (the jars by short name beside vdmcheck2.jar, the VDM models and the
# schema unpacked). Needs a Java runtime: Debian's default-jre-headless is
# installed if none is found.
set(VDMCHECK_DIR ${CMAKE_BINARY_DIR}/vdmcheck)
set(MAVEN_CENTRAL https://repo1.maven.org/maven2)
set(vdmcheck_jars
  "vdmcheck2|org/into-cps/vdmcheck/fmi2/vdmcheck2/1.1.3/vdmcheck2-1.1.3.jar|feae176bb0de1ca9ebd7a21dc433fca7c360c56a"
  "static-model|org/into-cps/vdmcheck/fmi2/static-model/1.1.3/static-model-1.1.3.jar|d9ac4bcc6947fc0f76fe82838085d3e104742178"
  "rule-model|org/into-cps/vdmcheck/fmi2/rule-model/1.1.3/rule-model-1.1.3.jar|6d168dc1680f7ed65d98c998fb634079da77dcfc"
  "xsd2vdm|org/into-cps/vdmcheck/xsd2vdm/1.1.3/xsd2vdm-1.1.3.jar|dc232db8f639629104b3bd5c6092b204f09bca1b"
  "fmuReader|org/into-cps/vdmcheck/fmuReader/1.1.3/fmuReader-1.1.3.jar|d468c18abffdcb782f31eda66fae03499fbb6ec4"
  "vdmj|dk/au/ece/vdmj/vdmj/4.5.0/vdmj-4.5.0.jar|5e12c40ea36eb23b8b3b64f2655846b268117350"
  "annotations|dk/au/ece/vdmj/annotations/4.5.0/annotations-4.5.0.jar|44d505bf4564b4a5e2733e084f5d261d3828e572")

if(NOT EXISTS ${VDMCHECK_DIR}/ready.stamp)
  foreach(entry IN LISTS vdmcheck_jars)
    string(REPLACE "|" ";" parts "${entry}")
    list(GET parts 0 short)
    list(GET parts 1 path)
    list(GET parts 2 sha1)
    file(DOWNLOAD ${MAVEN_CENTRAL}/${path} ${VDMCHECK_DIR}/${short}.jar EXPECTED_HASH SHA1=${sha1} STATUS status)
    list(GET status 0 code)
    if(code)
      message(WARNING "VDMCheck2: cannot download ${path}: ${status}")
    endif()
  endforeach()
  # the launcher reads these folders beside its jar
  foreach(pair "static-model;fmi2-static-model" "rule-model;fmi2-rule-model" "vdmcheck2;fmi2schema")
    list(GET pair 0 jar)
    list(GET pair 1 folder)
    file(ARCHIVE_EXTRACT INPUT ${VDMCHECK_DIR}/${jar}.jar DESTINATION ${VDMCHECK_DIR} PATTERNS ${folder})
  endforeach()
  file(TOUCH ${VDMCHECK_DIR}/ready.stamp)
endif()

find_program(JAVA java)
if(NOT JAVA)
  apt_install("VDMCheck2 needs Java" default-jre-headless)
  find_program(JAVA java)
endif()
set(VDMCHECK_JAR ${VDMCHECK_DIR}/vdmcheck2.jar)

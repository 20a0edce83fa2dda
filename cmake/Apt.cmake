# apt_install(<reason> <package>...): install Debian packages the project
# needs when a check found them missing (a clean CI machine has none).
function(apt_install reason)
  find_program(APT_GET apt-get)
  if(NOT APT_GET)
    message(WARNING "${reason}: no apt-get here to install ${ARGN}")
    return()
  endif()
  list(JOIN ARGN " " packages)
  message(STATUS "${reason}: installing Debian's ${packages}")
  execute_process(COMMAND sh -c "${APT_GET} update -qq && DEBIAN_FRONTEND=noninteractive ${APT_GET} install -y -qq --no-install-recommends ${packages}"
                  RESULT_VARIABLE failed OUTPUT_QUIET)
  if(failed)
    message(WARNING "apt-get install ${packages} failed")
  endif()
endfunction()

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
  # another configure (the sanitizer tree's, a second build tree) may hold
  # apt's lock: wait for it rather than fail
  set(wait "-o DPkg::Lock::Timeout=600")
  execute_process(COMMAND sh -c "${APT_GET} ${wait} update -qq && DEBIAN_FRONTEND=noninteractive ${APT_GET} ${wait} install -y -qq --no-install-recommends ${packages}"
                  RESULT_VARIABLE failed OUTPUT_QUIET)
  if(failed)
    message(WARNING "apt-get install ${packages} failed")
  endif()
endfunction()

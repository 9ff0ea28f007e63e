# Driver of the ParaView GUI test (cmake -P): starts the real `paraview` client under
# Xvfb, plays AmbientOcclusionMenu.xml and checks what the playback left behind.
#   -DPARAVIEW=<paraview> -DWITH_XVFB=<bash;.ci/with-xvfb.sh> -DTIMEOUT=<coreutils timeout>
#   -DPLUGIN_DIR=<dir of VolumetricAO.so> (empty: no plugin, the test must then fail)
#   -DTEST_SCRIPT=<configured playback xml> -DOUTPUT_DIR=<dir for status.txt and the PNG>
foreach(var IN ITEMS PARAVIEW WITH_XVFB TIMEOUT TEST_SCRIPT OUTPUT_DIR)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "FAILED: -D${var}=... is required")
  endif()
endforeach()

set(status_file "${OUTPUT_DIR}/status.txt")
set(screenshot "${OUTPUT_DIR}/AmbientOcclusionGUI.png")
file(REMOVE "${status_file}" "${screenshot}")
file(MAKE_DIRECTORY "${OUTPUT_DIR}" "${OUTPUT_DIR}/test-directory")

# The plugin is loaded the way a user would: PV_PLUGIN_PATH names its directory.
if(PLUGIN_DIR)
  set(ENV{PV_PLUGIN_PATH} "${PLUGIN_DIR}")
else()
  unset(ENV{PV_PLUGIN_PATH})
endif()
set(ENV{QT_QPA_PLATFORM} "xcb")
if(NOT DEFINED ENV{XDG_RUNTIME_DIR})
  set(ENV{XDG_RUNTIME_DIR} "${OUTPUT_DIR}/runtime")
  file(MAKE_DIRECTORY "$ENV{XDG_RUNTIME_DIR}")
  file(CHMOD "$ENV{XDG_RUNTIME_DIR}" PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE)
endif()

# `timeout` inside with-xvfb.sh kills paraview if it hangs, so the script still stops its Xvfb;
# the outer TIMEOUT is the last resort. --dr ignores the user's settings, --exit quits
# when the playback ends (the exit code is non-zero if an event could not be played).
execute_process(
  COMMAND ${WITH_XVFB} -s 1280x1024x24
    "${TIMEOUT}" -k 5 75
    "${PARAVIEW}" --dr "--test-directory=${OUTPUT_DIR}/test-directory"
      "--test-script=${TEST_SCRIPT}" --exit
  RESULT_VARIABLE rc
  OUTPUT_VARIABLE out
  ERROR_VARIABLE out
  TIMEOUT 85)
string(REGEX REPLACE "[^\n]*Available widget:[^\n]*\n" "" out_short "${out}")
message("${out_short}")

set(errors "")
if(NOT rc EQUAL 0)
  string(APPEND errors "paraview exited with '${rc}' (playback failed, timed out or crashed)\n")
endif()
if(EXISTS "${status_file}")
  file(READ "${status_file}" status)
  message("status.txt:\n${status}")
  if(NOT status MATCHES "VAO_GUI_OK")
    string(APPEND errors "the GUI pipeline check failed (see status.txt above)\n")
  endif()
else()
  string(APPEND errors "the GUI pipeline check did not run: no ${status_file}\n")
endif()
if(NOT EXISTS "${screenshot}")
  string(APPEND errors "no screenshot ${screenshot}\n")
endif()
if(errors)
  message(FATAL_ERROR "FAILED:\n${errors}")
endif()
message("passed: screenshot ${screenshot}")

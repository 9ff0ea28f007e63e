# The streaming test: -DVAO_STREAM=<vao_stream> -DWORK_DIR=<folder>. Generates a 97x83x61
# phantom, computes Gaussian CDF AO (R = 5) in one piece and in 7, and CDF Reconstruction
# (extrema too) in 1 and 5; the raw outputs must be identical and the reader must never
# have held all 61 slices when streaming.
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

function(run_stream)
  execute_process(COMMAND "${VAO_STREAM}" ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message("${out}${err}")
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "FAILED: vao_stream ${ARGN} exited with ${status}")
  endif()
  set(stream_output "${out}" PARENT_SCOPE)
endfunction()

run_stream(generate "${WORK_DIR}/phantom.mhd" 97 83 61)
foreach(case "gaussian;7" "cdf;5")
  list(GET case 0 method)
  list(GET case 1 pieces)
  run_stream(ao "${WORK_DIR}/phantom.mhd" "${WORK_DIR}/${method}_1.mhd" --pieces 1 --radius 5 --method ${method})
  run_stream(ao "${WORK_DIR}/phantom.mhd" "${WORK_DIR}/${method}_${pieces}.mhd" --pieces ${pieces} --radius 5
    --method ${method})
  string(REGEX MATCH "most slices read at once: ([0-9]+) of 61" found "${stream_output}")
  if(NOT found OR NOT CMAKE_MATCH_1 LESS 61)
    message(FATAL_ERROR "FAILED: ${method} in ${pieces} pieces read the whole volume at once (${found})")
  endif()
  execute_process(COMMAND "${CMAKE_COMMAND}" -E compare_files "${WORK_DIR}/${method}_1.raw"
    "${WORK_DIR}/${method}_${pieces}.raw" RESULT_VARIABLE different)
  if(different)
    message(FATAL_ERROR "FAILED: ${method} in ${pieces} pieces differs from one piece")
  endif()
  message("${method}: ${pieces} pieces equal one piece; ${found}")
endforeach()
message("streaming: passed")

# The streaming test: -DVAO_STREAM=<vao_stream> -DWORK_DIR=<folder>. Generates a 97x83x61
# phantom, computes Gaussian CDF AO (R = 5) in one piece and in 7, CDF Reconstruction
# (extrema too) in 1 and 5, and Histogram CDF (its thresholds read slab by slab first) in 1
# and 6; the raw outputs must be identical, the reader must never
# have held all 61 slices when streaming, and both files, read back with VTK's MetaImage
# reader, must give the filter's in-memory result exactly. Bad files and arguments must
# fail with exit code 2 and a message.
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
foreach(case "gaussian;7" "cdf;5" "histogram;6")
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
  run_stream(check "${WORK_DIR}/phantom.mhd" "${WORK_DIR}/${method}_${pieces}.mhd" --radius 5 --method ${method})
  if(NOT stream_output MATCHES "max difference 0 over 491111 voxels")
    message(FATAL_ERROR "FAILED: ${method} in ${pieces} pieces, read back, differs from the in-memory filter")
  endif()
  message("${method}: ${pieces} pieces equal one piece and the in-memory filter; ${found}")
endforeach()

function(expect_refusal text)
  execute_process(COMMAND "${VAO_STREAM}" ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 2 OR NOT "${out}${err}" MATCHES "${text}")
    message(FATAL_ERROR "FAILED: vao_stream ${ARGN}: exit ${status} (want 2), output: ${out}${err}")
  endif()
  message("refused as expected: vao_stream ${ARGN}")
endfunction()
file(WRITE "${WORK_DIR}/compressed.mhd"
  "NDims = 3\nDimSize = 4 4 4\nElementType = MET_SHORT\nCompressedData = True\nElementDataFile = x.raw\n")
file(WRITE "${WORK_DIR}/local.mhd" "NDims = 3\nDimSize = 4 4 4\nElementType = MET_SHORT\nElementDataFile = LOCAL\n")
expect_refusal("cannot open" ao "${WORK_DIR}/missing.mhd" "${WORK_DIR}/out.mhd")
expect_refusal("compressed data cannot be read in pieces" ao "${WORK_DIR}/compressed.mhd" "${WORK_DIR}/out.mhd")
expect_refusal("separate raw file" ao "${WORK_DIR}/local.mhd" "${WORK_DIR}/out.mhd")
expect_refusal("usage" ao "${WORK_DIR}/phantom.mhd" "${WORK_DIR}/out.mhd" --pieces 0)
expect_refusal("usage" ao "${WORK_DIR}/phantom.mhd" "${WORK_DIR}/out.mhd" --radius -1)
expect_refusal("usage" ao "${WORK_DIR}/phantom.mhd" "${WORK_DIR}/out.mhd" --method box)
expect_refusal("cannot open" check "${WORK_DIR}/missing.mhd" "${WORK_DIR}/gaussian_7.mhd")
message("streaming: passed")

# SPDX-License-Identifier: MIT
# Run by CTest (InstallConsumer.FindPackage): installs BUILD_DIR into WORK_DIR/prefix, then builds the
# consumer project in SOURCE_DIR with only CMAKE_PREFIX_PATH set, and runs it (it exits 0 when its two
# solves are exact). Any failing step fails the test with that step's output.
file(REMOVE_RECURSE ${WORK_DIR})
function(step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message("${out}")
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "failed (${status}): ${ARGN}\n${err}")
  endif()
endfunction()
set(config ${CONFIG})
if(NOT config)
  set(config Release)
endif()
step(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix --config ${config})
# A library built with the sanitizers (scripts/test.sh --sanitize) needs their runtimes in the program too.
set(sanitize_flags)
if(SANITIZE)
  set(sanitize_flags -DCMAKE_CXX_FLAGS=-fsanitize=address,undefined -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined)
endif()
step(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix ${sanitize_flags})
step(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
step(${WORK_DIR}/build/consumer)

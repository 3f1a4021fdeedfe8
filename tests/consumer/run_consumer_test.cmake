# Installs the FSS build tree into a fresh prefix, builds tests/consumer against it and runs it.
# Inputs: FSS_BINARY_DIR, CONSUMER_SOURCE_DIR, WORK_DIR, GENERATOR, MESH.
file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
execute_process(COMMAND ${CMAKE_COMMAND} --install "${FSS_BINARY_DIR}" --prefix "${prefix}" --component dev
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(rc)
  message(FATAL_ERROR "installing FSS into ${prefix} failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --install "${FSS_BINARY_DIR}" --prefix "${prefix}"
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(rc)
  message(FATAL_ERROR "installing FSS into ${prefix} failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S "${CONSUMER_SOURCE_DIR}" -B "${WORK_DIR}/build" -G "${GENERATOR}"
                        -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the consumer project against ${prefix} failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build "${WORK_DIR}/build" RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building the consumer project failed (${rc})")
endif()
execute_process(COMMAND "${WORK_DIR}/build/fss_consumer" "${MESH}" RESULT_VARIABLE rc OUTPUT_VARIABLE out)
message(STATUS "consumer printed: ${out}")
if(rc OR NOT out MATCHES "vertices=4 faces=4")
  message(FATAL_ERROR "the consumer program failed (${rc}) or printed the wrong counts: ${out}")
endif()
# The SHA-256 through FSS (libcrypto, found through FSS's package) equals CMake's own.
file(SHA256 "${MESH}" expected_sha)
if(NOT out MATCHES "sha256=${expected_sha}")
  message(FATAL_ERROR "the consumer's SHA-256 of ${MESH} differs from CMake's ${expected_sha}: ${out}")
endif()
if(NOT out MATCHES "self_intersections=0")
  message(FATAL_ERROR "the consumer counted self-intersections of a tetrahedron: ${out}")
endif()

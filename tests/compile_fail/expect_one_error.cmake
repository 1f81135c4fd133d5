# Builds TARGET in BUILD_DIR, which must fail with exactly one compiler error whose text matches
# MESSAGE: an entry point called with a type that is not a mesh reports check_mesh's
# static_assert and nothing else (no cascade from the entry points' bodies).
execute_process(COMMAND ${CMAKE_COMMAND} --build ${BUILD_DIR} --target ${TARGET}
                OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
set(log "${out}${err}")
if(rc EQUAL 0)
  message(FATAL_ERROR "${TARGET} compiled; it must not")
endif()
string(REGEX MATCHALL "error:" errors "${log}")
list(LENGTH errors count)
if(NOT count EQUAL 1)
  message(FATAL_ERROR "${TARGET}: ${count} compiler errors, expected 1:\n${log}")
endif()
string(REGEX MATCH "${MESSAGE}" named "${log}")
if(NOT named)
  message(FATAL_ERROR "${TARGET}: the one error does not name what is missing (${MESSAGE}):\n${log}")
endif()
message(STATUS "${TARGET}: one error, naming what is missing")

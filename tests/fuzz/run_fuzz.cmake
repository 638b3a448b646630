# Runs the libFuzzer target for a bounded time: new inputs go to WORK (in the build tree), the
# committed corpora are read-only seeds.
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${FUZZER} -max_total_time=60 -timeout=10 -rss_limit_mb=4096 ${WORK} ${SEEDS}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${FUZZER} found a failing input (exit ${rc}); see crash-* files")
endif()

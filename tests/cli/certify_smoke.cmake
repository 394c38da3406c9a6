# dock-sim certify, CI size: 60 robots drawn from the family on the default scenario, seed 1. The draw and the runs
# are deterministic, so every one of them must dock (a regression check), and the JSON must not depend on --jobs.
# Then one trial written out and replayed with dock-sim run, and an argument error (exit 2).
# Inputs: -DDOCKSIM=<dock-sim> -DSCENARIO=<default.toml> -DWORK=<scratch dir>.
file(MAKE_DIRECTORY ${WORK})

execute_process(COMMAND ${DOCKSIM} certify ${SCENARIO} --trials 60 --seed 1 --jobs 2 --json
  RESULT_VARIABLE rc OUTPUT_VARIABLE two ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "certify: exit ${rc}\n${err}")
endif()
string(JSON ok GET "${two}" successes)
string(JSON failures GET "${two}" failures)
if(NOT ok EQUAL 60)
  message(FATAL_ERROR "certify: ${ok} of 60 robots docked; failures (each with its replay command):\n${failures}")
endif()
string(JSON lower GET "${two}" lower_bound_95)
if(NOT lower MATCHES "^0\\.95")
  message(FATAL_ERROR "certify: 60 of 60 should demonstrate 0.05^(1/60) = 0.9513, got ${lower}")
endif()
execute_process(COMMAND ${DOCKSIM} certify ${SCENARIO} --trials 60 --seed 1 --jobs 1 --json
  RESULT_VARIABLE rc OUTPUT_VARIABLE one ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT one STREQUAL two)
  message(FATAL_ERROR "certify: the result depends on --jobs (exit ${rc})")
endif()

# Trial 7 alone (beyond the default --trials too: a trial depends on the seed and its index only): its scenario
# file, replayed by dock-sim run with the seed its header names.
execute_process(COMMAND ${DOCKSIM} certify ${SCENARIO} --seed 1 --trials 1 --trial 7 --write ${WORK}/trial7.toml
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "certify --trial: exit ${rc}\n${err}")
endif()
file(STRINGS ${WORK}/trial7.toml header LIMIT_COUNT 1)
if(NOT header MATCHES "--seed ([0-9]+)$")
  message(FATAL_ERROR "certify --write: no replay seed in the header: ${header}")
endif()
execute_process(COMMAND ${DOCKSIM} run ${WORK}/trial7.toml --seed ${CMAKE_MATCH_1} --json
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(JSON confirmed ERROR_VARIABLE jerr GET "${out}" charging_confirmed)
if(NOT rc EQUAL 0 OR NOT confirmed STREQUAL "ON")
  message(FATAL_ERROR "replaying trial 7: exit ${rc}, charging_confirmed '${confirmed}'\n${err}")
endif()

execute_process(COMMAND ${DOCKSIM} certify ${SCENARIO} --write ${WORK}/x.toml
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--write needs --trial")
  message(FATAL_ERROR "certify --write without --trial: exit ${rc}, want 2 with a message\n${err}")
endif()
message(STATUS "certify: 60 / 60 robots docked, independent of --jobs; a trial replays alone")

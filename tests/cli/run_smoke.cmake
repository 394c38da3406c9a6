# dock-sim run / montecarlo smoke test: one docking in the default scenario (exit 0, charging confirmed in its JSON),
# a tiny Monte Carlo (exit 0, table printed) and a scenario error (unknown key: exit 2 with line:col).
# Inputs: -DDOCKSIM=<dock-sim> -DSCENARIO=<default.toml> -DWORK=<scratch dir>.
file(MAKE_DIRECTORY ${WORK})

execute_process(COMMAND ${DOCKSIM} run ${SCENARIO} --controller smooth --seed 1 --json
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "run: exit ${rc}\n${out}\n${err}")
endif()
string(JSON confirmed ERROR_VARIABLE jerr GET "${out}" charging_confirmed)
if(jerr OR NOT confirmed STREQUAL "ON")
  message(FATAL_ERROR "run: charging_confirmed is '${confirmed}' (${jerr})\n${out}")
endif()

execute_process(COMMAND ${DOCKSIM} montecarlo ${SCENARIO} --trials 4 --controller smooth --jobs 2
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "montecarlo: exit ${rc}\n${out}\n${err}")
endif()
if(NOT out MATCHES "smooth")
  message(FATAL_ERROR "montecarlo: no table row for smooth\n${out}")
endif()

# Unknown key on line 3, column 1.
file(WRITE ${WORK}/bad_key.toml "name = \"bad\"\nseed = 1\nno_such_key = 3\n")
execute_process(COMMAND ${DOCKSIM} run ${WORK}/bad_key.toml
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2)
  message(FATAL_ERROR "bad scenario: exit ${rc}, want 2\n${out}\n${err}")
endif()
if(NOT err MATCHES "3:1" OR NOT err MATCHES "no_such_key")
  message(FATAL_ERROR "bad scenario: message lacks line:col 3:1 or the key\n${err}")
endif()
message(STATUS "run, montecarlo and scenario error OK")

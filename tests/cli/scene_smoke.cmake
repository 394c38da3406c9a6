cmake_minimum_required(VERSION 3.25)
# ctest: `dock-sim scene` with its defaults finds the dock, reports every detector as JSON and writes an SVG;
# `dock-sim profile` draws a profile and a reflector profile's tape layout.
# Inputs: -DDOCKSIM=<dock-sim> -DWORK=<scratch dir>
file(MAKE_DIRECTORY "${WORK}")
file(REMOVE "${WORK}/scene.svg" "${WORK}/profile.svg")
execute_process(COMMAND "${DOCKSIM}" scene --json --svg "${WORK}/scene.svg" RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "dock-sim scene exited ${rc}: ${err}\n${out}")
endif()
string(JSON n LENGTH "${out}" detectors)
if(NOT n EQUAL 3)
  message(FATAL_ERROR "expected 3 detectors, got ${n}: ${out}")
endif()
string(JSON name GET "${out}" detectors 0 detector)
string(JSON found GET "${out}" detectors 0 found)
string(JSON elat GET "${out}" detectors 0 error lateral_m)
if(NOT name STREQUAL "estimator" OR NOT found)
  message(FATAL_ERROR "estimator should find the default scene's dock: ${out}")
endif()
# plate-v: neither the breakpoint nor the V-marker detector applies.
string(JSON app GET "${out}" detectors 1 applicable)
if(app)
  message(FATAL_ERROR "breakpoint detector should be n/a for plate-v: ${out}")
endif()
file(READ "${WORK}/scene.svg" svg)
if(NOT svg MATCHES "^<\\?xml" OR NOT svg MATCHES "</svg>\n$" OR NOT svg MATCHES "estimator fit")
  message(FATAL_ERROR "scene.svg is not the expected SVG")
endif()
execute_process(COMMAND "${DOCKSIM}" profile --name breakpoint --svg "${WORK}/profile.svg" RESULT_VARIABLE rc
                OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT EXISTS "${WORK}/profile.svg" OR NOT out MATCHES "12 vertices, width 300.0 mm, depth 100.0 mm")
  message(FATAL_ERROR "dock-sim profile --name breakpoint: exit ${rc}: ${out}")
endif()
# A reflector profile's tape layout at 1:1: one bar per taped segment, each stripe black and dimensioned; a profile
# without stripes has no layout (exit 2).
execute_process(COMMAND "${DOCKSIM}" profile --name "${SRC}/tools/scenarios/profiles/plate-v-code-a.toml"
                        --layout "${WORK}/layout.svg" RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "reflector 1: segment 1, 200.0-300.0 mm from vertex 1")
  message(FATAL_ERROR "dock-sim profile --layout: exit ${rc}: ${out}")
endif()
file(READ "${WORK}/layout.svg" layout)
string(REGEX MATCHALL "fill=\"black\"" tape "${layout}")
list(LENGTH tape n_tape)
if(NOT layout MATCHES "width=\"330.0mm\"" OR NOT n_tape EQUAL 2 OR NOT layout MATCHES ">200.0</text>")
  message(FATAL_ERROR "layout.svg is not the 1:1 layout of plate-v-code-a (${n_tape} stripes)")
endif()
execute_process(COMMAND "${DOCKSIM}" profile --name plate-v --layout "${WORK}/none.svg" RESULT_VARIABLE rc
                ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "has no reflector stripes")
  message(FATAL_ERROR "dock-sim profile --layout on an untaped profile: exit ${rc}: ${err}")
endif()
message(STATUS "scene: estimator lateral error ${elat} m; SVGs written")

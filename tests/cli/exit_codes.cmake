cmake_minimum_required(VERSION 3.25)
# ctest: dock-sim's documented exit statuses and error messages.
#  detect: 0 when the file was readable (malformed lines reported on stderr with their line numbers, then skipped),
#          2 for a bad profile / bad argument / unreadable file.
#  scene / profile: 2 for a bad profile (message with file:line:column for TOML errors).
#  every command-line error CLI11 finds (unknown option or subcommand, bad value, out of a documented range, negative
#  seed): 2 with its message; --help: 0.
# Inputs: -DDOCKSIM=<dock-sim> -DDIR=<tests/cli> -DSCANS=<sample.jsonl> -DWORK=<scratch dir>
foreach(v DOCKSIM DIR SCANS WORK)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "exit_codes: -D${v}=... missing")
  endif()
endforeach()
file(MAKE_DIRECTORY "${WORK}")

function(expect_run want_rc stderr_regex)
  execute_process(COMMAND "${DOCKSIM}" ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL want_rc)
    message(FATAL_ERROR "dock-sim ${ARGN}: exit ${rc}, wanted ${want_rc}\nstdout: ${out}\nstderr: ${err}")
  endif()
  if(NOT stderr_regex STREQUAL "" AND NOT err MATCHES "${stderr_regex}")
    message(FATAL_ERROR "dock-sim ${ARGN}: stderr does not match '${stderr_regex}':\n${err}")
  endif()
  set(last_out "${out}" PARENT_SCOPE)
endfunction()

# A file with good scans around garbage: the garbage is reported with its line and skipped; every good scan still
# gives output. Built from the first sample scan so it stays valid whatever the sample holds.
file(STRINGS "${SCANS}" sample_lines LIMIT_COUNT 1)
list(GET sample_lines 0 good)
file(WRITE "${WORK}/malformed.jsonl"
  "${good}\n{not json\n\n{\"stamp_us\":-1,\"angle_min_rad\":0,\"angle_increment_rad\":0.01,\"ranges_m\":[1]}\n${good}\n[1,2]\n")
expect_run(0 "line 2:.*line 4:.*line 6:.*2 scan\\(s\\), 3 malformed line\\(s\\) skipped" detect --scans "${WORK}/malformed.jsonl"
           --profile plate-v --detector estimator)
string(REGEX MATCHALL "\"detector\":\"estimator\"" hits "${last_out}")
list(LENGTH hits n)
if(NOT n EQUAL 2)
  message(FATAL_ERROR "malformed.jsonl: expected 2 estimator lines, got ${n}:\n${last_out}")
endif()
if(NOT last_out MATCHES "\"scan\":1,\"line\":5,")
  message(FATAL_ERROR "malformed.jsonl: second good scan should be scan 1 from line 5:\n${last_out}")
endif()

expect_run(2 "cannot open" detect --scans "${WORK}/does-not-exist.jsonl")
expect_run(2 "unknown profile 'nope'" detect --scans "${SCANS}" --profile nope)
expect_run(2 "bad pose" detect --scans "${SCANS}" --mount 1,2)
expect_run(2 "unknown detector" detect --scans "${SCANS}" --detector hough)
expect_run(2 "--scans FILE is required" detect)
expect_run(2 "bad_profile.toml:3:3: unknown key 'depth'" detect --scans "${SCANS}" --profile "${DIR}/bad_profile.toml")
expect_run(2 "bad_profile.toml:3:3: unknown key 'depth'" scene --profile "${DIR}/bad_profile.toml")
expect_run(2 "unknown lidar" scene --lidar hokuyo)
expect_run(2 "bad_profile.toml:3:3" profile --name "${DIR}/bad_profile.toml")

# dock-sim replay: a file that is no loop record, or none at all, is refused with its reason (exit 2).
expect_run(2 "not a dockcore loop record" replay "${DIR}/bad_profile.toml")
expect_run(2 "does-not-exist.rec: No such file" replay "${WORK}/does-not-exist.rec")
expect_run(2 "record is required" replay)

# Command-line errors: exit 2 (never CLI11's own codes 104-114) with CLI11's message; --help exits 0.
expect_run(0 "" --help)
expect_run(0 "" scene --help)
expect_run(2 "A subcommand is required")
expect_run(2 "unknown subcommand 'fly' \\(valid: scene, profile, detect, perception, run, montecarlo, certify, soak, features, params, replay\\)" fly)
expect_run(2 "--bogus" scene --bogus)
expect_run(2 "unknown option '--bogus'" --bogus)
expect_run(2 "--clutter" scene --clutter x)
expect_run(2 "--clutter: Value 9 not in range 0 to 3" scene --clutter 9)
expect_run(2 "--clutter: Value 4 not in range 0 to 3" perception --clutter 4)
expect_run(2 "--look-alikes" scene --look-alikes -1)
expect_run(2 "--seed: must be a non-negative integer" scene --seed -1)
expect_run(2 "--seed: must be a non-negative integer" perception --seed -5)
expect_run(2 "--seed: must be a non-negative integer" features --seed -1)
expect_run(2 "--seed: must be a non-negative integer" certify "${DIR}/../../tools/scenarios/default.toml" --seed -1)
expect_run(2 "--seed" detect --scans "${SCANS}" --seed 1)

# With a mount the poses move into the robot frame: lidar 0.1 m ahead of the robot centre, turned 180°.
expect_run(0 "" detect --scans "${SCANS}" --detector estimator)
string(REGEX MATCH "\"x_m\":([-0-9.e]+),\"y_m\":([-0-9.e]+)" m "${last_out}")
set(lx "${CMAKE_MATCH_1}")
expect_run(0 "" detect --scans "${SCANS}" --detector estimator --mount 0.1,0,3.141592653589793)
string(REGEX MATCH "\"x_m\":([-0-9.e]+),\"y_m\":([-0-9.e]+)" m "${last_out}")
set(rx "${CMAKE_MATCH_1}")
# robot x = 0.1 - lidar x: compare at millimetre precision as integers.
string(REGEX REPLACE "^(-?[0-9]+)\\.([0-9][0-9][0-9]).*" "\\1\\2" lx_mm "${lx}")
string(REGEX REPLACE "^(-?[0-9]+)\\.([0-9][0-9][0-9]).*" "\\1\\2" rx_mm "${rx}")
math(EXPR sum "${lx_mm} + ${rx_mm}")
if(sum LESS 99 OR sum GREATER 101)
  message(FATAL_ERROR "mount: lidar-frame x ${lx} and robot-frame x ${rx} should add up to 0.100")
endif()
# The rendered camera: asked of a scenario without a camera, with a tag family libapriltag lacks, or of soak: exit 2
# naming the key (a dock-sim without libapriltag names that instead).
set(scenarios "${DIR}/../../tools/scenarios")
expect_run(2 "--camera-render: the scenario has no camera" run "${scenarios}/pushed.toml" --camera-render)
file(WRITE "${WORK}/bad_tag.toml" "[robot.camera]\nenabled = true\nrender = true\n[dock.tag]\nfamily = \"tag99h99\"\n")
expect_run(2 "bad_tag.toml: (dock.tag: .*tag99h99|.*libapriltag)" run "${WORK}/bad_tag.toml")
expect_run(2 "bad_tag.toml: (dock.tag: .*tag99h99|.*libapriltag)" montecarlo "${WORK}/bad_tag.toml" --trials 1)
file(WRITE "${WORK}/rendered.toml" "[robot.camera]\nenabled = true\nrender = true\n")
expect_run(2 "renders camera frames" soak "${WORK}/rendered.toml" --cycles 1)
message(STATUS "exit codes and messages as documented")

# dock-sim soak on tools/scenarios/lidar-miscalibrated.toml: the lidar sits 1 cm / 1 cm / 1° off its configured mount.
# Without the mount calibration swing ([task] calibrate_mount = false) the first docking finds the contacts only by the
# retries' sideways search (well over 40 s). With [task] remember_aim (the default) every later docking starts from
# the aim that closed them and docks at once; with it off, every docking searches again. With the swing (the
# scenario as shipped) the first docking measures the mount after its first miss and docks on the next attempt.
# Inputs: -DDOCKSIM=<dock-sim> -DSCENARIO=<lidar-miscalibrated.toml> -DWORK=<dir>.
file(MAKE_DIRECTORY ${WORK})
set(slow_s 40)

# The four dock times of `file`; a docking that failed (the search ran out of attempts) counts as searching: its time
# is given as ${slow_s}. must_dock: every cycle must dock (exit 0).
function(soak_times file must_dock out_var)
  # Four cycles say nothing about drift (cli_soak checks it): its limits are opened, so exit 0 means every cycle docked.
  execute_process(COMMAND ${DOCKSIM} soak ${file} --cycles 4 --json --max-drift-lateral-mm 1000 --max-drift-yaw-deg 180
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(must_dock AND NOT rc EQUAL 0)
    message(FATAL_ERROR "soak ${file}: exit ${rc} (every cycle must dock)\n${out}\n${err}")
  endif()
  set(times "")
  foreach(i RANGE 3)
    string(JSON ok ERROR_VARIABLE jerr GET "${out}" per_cycle ${i} success)
    if(jerr)
      message(FATAL_ERROR "soak ${file}: no per_cycle ${i} (${jerr})\n${out}\n${err}")
    endif()
    if(ok)
      string(JSON t GET "${out}" per_cycle ${i} dock_time_s)
    else()
      set(t ${slow_s})
    endif()
    list(APPEND times ${t})
  endforeach()
  set(${out_var} "${times}" PARENT_SCOPE)
endfunction()

file(READ ${SCENARIO} text)
file(WRITE ${WORK}/search.toml "${text}\n[task]\ncalibrate_mount = false\n")
soak_times(${WORK}/search.toml TRUE on)
message(STATUS "remember_aim on: dock times ${on} s")
list(GET on 0 first)
if(first LESS ${slow_s})
  message(FATAL_ERROR "the first docking took ${first} s: the scenario no longer needs the search")
endif()
foreach(i 1 2 3)
  list(GET on ${i} t)
  if(NOT t LESS ${slow_s})
    message(FATAL_ERROR "docking ${i} took ${t} s: it searched again instead of starting from the remembered aim")
  endif()
endforeach()

file(WRITE ${WORK}/forget.toml "${text}\n[task]\ncalibrate_mount = false\nremember_aim = false\n")
soak_times(${WORK}/forget.toml FALSE off)
message(STATUS "remember_aim off: dock times ${off} s")
list(GET off 1 t)
if(t LESS ${slow_s})
  message(FATAL_ERROR "without remember_aim docking 1 took ${t} s: the check above cannot fail")
endif()

soak_times(${SCENARIO} TRUE swing)
message(STATUS "calibration swing (as shipped): dock times ${swing} s")
list(GET swing 0 t)
if(NOT t LESS ${slow_s})
  message(FATAL_ERROR "with the calibration swing the first docking took ${t} s: it searched instead of measuring")
endif()

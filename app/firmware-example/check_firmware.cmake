# Fails when the linked firmware contains heap, exception or RTTI machinery.
#   -DNM=<arm-none-eabi-nm> -DSIZE=<arm-none-eabi-size> -DELF=<firmware.elf> -DMAP=<linker map>
# The linked image is what ships, so it is checked rather than the archives: everything the linker pulled in from
# core, libstdc++/libsupc++, newlib and libgcc shows up here.
cmake_minimum_required(VERSION 3.25)
foreach(v NM SIZE ELF MAP)
  if(NOT EXISTS "${${v}}")
    message(FATAL_ERROR "${v}=${${v}} does not exist")
  endif()
endforeach()

execute_process(COMMAND ${NM} ${ELF} OUTPUT_VARIABLE syms RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "nm failed on ${ELF}")
endif()
# Mangled names: _Znwj/_Znaj operator new (32-bit size_t), _Zdl/_Zda operator delete, _ZTI/_ZTS typeinfo.
set(forbidden
  "malloc" "_malloc_r" "calloc" "_calloc_r" "realloc" "_realloc_r" "free" "_free_r" "_sbrk" "_sbrk_r"
  "__cxa_throw" "__cxa_allocate_exception" "__cxa_begin_catch" "__cxa_rethrow" "__gxx_personality_v0"
  "__dynamic_cast")
set(forbidden_prefix "_Znw" "_Zna" "_Zdl" "_Zda" "_ZTI" "_ZTS" "_Unwind_" "__aeabi_unwind_cpp_pr" "__gnu_unwind")
set(bad "")
string(REPLACE "\n" ";" lines "${syms}")
list(LENGTH lines nsyms)
foreach(line IN LISTS lines)
  if(NOT line MATCHES "^([0-9a-fA-F]+ +)?([A-Za-z]) (.+)$")
    continue()
  endif()
  set(name "${CMAKE_MATCH_3}")
  if(name IN_LIST forbidden)
    list(APPEND bad "${line}")
    continue()
  endif()
  foreach(p IN LISTS forbidden_prefix)
    string(FIND "${name}" "${p}" at)
    if(at EQUAL 0)
      list(APPEND bad "${line}")
      break()
    endif()
  endforeach()
endforeach()

# -fno-exceptions leaves .ARM.exidx "cannot unwind" entries (8 bytes per function) but no .ARM.extab unwind data.
execute_process(COMMAND ${SIZE} -A ${ELF} OUTPUT_VARIABLE sections)
if(sections MATCHES "\n\\.ARM\\.extab +([0-9]+)" AND NOT CMAKE_MATCH_1 EQUAL 0)
  list(APPEND bad ".ARM.extab holds ${CMAKE_MATCH_1} bytes of unwind instructions")
endif()

# Which library members the link pulled in and why (the map's first section), for the report.
file(READ ${MAP} map)
string(FIND "${map}" "\nDiscarded input sections" end)
string(SUBSTRING "${map}" 0 ${end} pulled)
string(REGEX MATCHALL "lib[a-z_+]+\\.a\\(([^)]+)\\)" members "${pulled}")
list(REMOVE_DUPLICATES members)
list(LENGTH members nmembers)

if(bad)
  string(REPLACE ";" "\n  " bad "${bad}")
  message(FATAL_ERROR "firmware pulls in heap/exception/RTTI machinery:\n  ${bad}")
endif()
string(REPLACE ";" " " members "${members}")
message(STATUS "firmware: ${nsyms} symbols checked, no heap/exception/RTTI; library members linked (${nmembers}): ${members}")
string(REGEX MATCH "\n\\.text +[0-9]+" t "${sections}")
string(REGEX MATCH "\n\\.bss +[0-9]+" b "${sections}")
message(STATUS "firmware sections:${t}${b}")

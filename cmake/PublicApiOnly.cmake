# SPDX-License-Identifier: LGPL-2.1-or-later
# The programs of samples/ filter through libdefocus' public API (include/defocus/) alone: their
# files, and every header of the tree they reach through quoted includes (sources/, sinks/,
# samples/), include nothing of filter/ or bench/, the library's inside and the benchmarks'
# apparatus. The sources' and sinks' .cpp files are theirs (the I/O library logs as libdefocus
# does), and are not followed. Run by the build before the programs compile (samples/CMakeLists.txt):
#   cmake -DSOURCE_DIR=. "-DFILES=samples/defocus.cpp;..." -DSTAMP=out.stamp -P cmake/PublicApiOnly.cmake
cmake_minimum_required(VERSION 3.25)
set(pending ${FILES})
set(seen "")
set(refused 0)
while(pending)
  list(POP_FRONT pending file)
  if(file IN_LIST seen)
    continue()
  endif()
  list(APPEND seen ${file})
  file(STRINGS ${SOURCE_DIR}/${file} lines REGEX "^[ \t]*#[ \t]*include[ \t]*\"")
  foreach(line IN LISTS lines)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"([^\"]+)\".*$" "\\1" header "${line}")
    if(header MATCHES "^(filter|bench)/")
      message(SEND_ERROR "${file} includes ${header}: the programs of samples/ use libdefocus' public API "
                         "(include/defocus/); what they need of the filter belongs there")
      math(EXPR refused "${refused} + 1")
    elseif(EXISTS ${SOURCE_DIR}/${header} AND NOT header MATCHES "^defocus/")
      list(APPEND pending ${header})
    endif()
  endforeach()
endwhile()
if(refused GREATER 0)
  message(FATAL_ERROR "public API only: ${refused} includes of filter/ or bench/ in the programs")
endif()
list(LENGTH seen checked)
if(STAMP)
  file(WRITE ${STAMP} "${checked} files of the programs checked: public API only\n")
endif()

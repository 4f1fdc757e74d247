# SPDX-License-Identifier: LGPL-2.1-or-later
# The window only shows frames: sinks/DisplaySink.hpp and .cpp may include of filter/ only the
# logger, and nothing of samples/ (what a key does to the lens, the focus or the
# view is samples/PreviewController's). Defect: the sink deciding keys, lens or focus again,
# through filter/Pipeline.hpp, Autofocus.hpp, SceneAnalysis.hpp, Settings.hpp or the controller.
#   cmake -DSOURCE_DIR=. -P tests/display-sink-includes.cmake      (CTest: display_sink_includes)
cmake_minimum_required(VERSION 3.25)
set(allowed filter/Log.hpp)
set(found 0)
set(refused 0)
foreach(file sinks/DisplaySink.hpp sinks/DisplaySink.cpp)
  if(NOT EXISTS ${SOURCE_DIR}/${file})
    message(FATAL_ERROR "display_sink_includes: ${SOURCE_DIR}/${file} is missing")
  endif()
  file(STRINGS ${SOURCE_DIR}/${file} includes REGEX "^[ \t]*#[ \t]*include[ \t]*[\"<](filter|samples)/")
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*[\"<]([^\">]+)[\">].*$" "\\1" header "${line}")
    if(NOT header IN_LIST allowed)
      message(SEND_ERROR "${file} includes ${header}: the window shows frames and reports keys, it does not "
                         "drive the filter (allowed of filter/: ${allowed})")
      math(EXPR refused "${refused} + 1")
    endif()
    math(EXPR found "${found} + 1")
  endforeach()
endforeach()
if(refused GREATER 0)
  message(FATAL_ERROR "display_sink_includes: ${refused} of ${found} includes of filter/ or samples/ refused")
endif()
message(STATUS "display_sink_includes: ${found} includes of filter/ or samples/, all allowed")

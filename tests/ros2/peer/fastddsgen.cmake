# SPDX-License-Identifier: Apache-2.0
# cmake -P script: runs fastddsgen once on ROOTS (IDL files relative to IDL_ROOT, comma-separated) and files
# the generated sources of every type in FILES (the roots and all they include) under OUT_DIR as
# <package>/msg/<Type>{.h,.cxx,PubSubTypes.h,PubSubTypes.cxx}. fastddsgen writes every type it generates into
# one directory, but its headers include a type of another package as "<package>/msg/<Type>.h": the layout of
# idl/ros2 is what makes them compile. One run, not one per package: each run costs a JVM start and a parse
# of everything included (≈ 12 s for all the peer's types on one core).
cmake_minimum_required(VERSION 3.25)
foreach(variable FASTDDSGEN IDL_ROOT OUT_DIR ROOTS FILES)
  if(NOT DEFINED ${variable})
    message(FATAL_ERROR "fastddsgen.cmake: -D${variable}=... missing")
  endif()
endforeach()
string(REPLACE "," ";" roots "${ROOTS}")
string(REPLACE "," ";" files "${FILES}")

set(staging ${OUT_DIR}/staging)
file(REMOVE_RECURSE ${staging})
file(MAKE_DIRECTORY ${staging})
set(inputs "")
foreach(root IN LISTS roots)
  list(APPEND inputs ${IDL_ROOT}/${root}.idl)
endforeach()
execute_process(COMMAND ${FASTDDSGEN} -replace -I ${IDL_ROOT} -d ${staging} ${inputs}
  RESULT_VARIABLE status OUTPUT_VARIABLE log ERROR_VARIABLE log)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "fastddsgen failed (${status}):\n${log}")
endif()

foreach(file IN LISTS files)
  get_filename_component(type ${file} NAME)
  get_filename_component(package_dir ${file} DIRECTORY)
  file(MAKE_DIRECTORY ${OUT_DIR}/${package_dir})
  foreach(suffix .h .cxx PubSubTypes.h PubSubTypes.cxx)
    # fastddsgen also reports some errors (a type it cannot parse) with status 0 and no file.
    if(NOT EXISTS ${staging}/${type}${suffix})
      message(FATAL_ERROR "fastddsgen made no ${type}${suffix}:\n${log}")
    endif()
    file(RENAME ${staging}/${type}${suffix} ${OUT_DIR}/${package_dir}/${type}${suffix})
  endforeach()
endforeach()
file(REMOVE_RECURSE ${staging})

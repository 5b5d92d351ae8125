# localize_archive.cmake - makes the installed libgrainpack.a define, as global names, only
# the public functions. Its objects are linked into one (ld -r), in which the global
# symbols of hidden visibility - the library's own functions not marked GP_API (front_*,
# the bucket grid, ...) - become local: a program that defines its own front_init links,
# and the archive offers the names the shared library exports. Weak and unique symbols
# (the C++ template instantiations of CGAL, Boost and the standard library) stay as they
# are: they sit in COMDAT groups, which the linker merges with a program's own copies as
# C++ intends; made local, a discarded copy would leave dangling references. With
# STRIP_LTO, the LTO bytecode goes first (see core/CMakeLists.txt): the installed archive
# holds plain machine code.
# Usage: cmake -DARCHIVE=... -DLINKER=ld -DOBJCOPY=objcopy -DREADELF=readelf -DAR=ar
#              [-DSTRIP_LTO=ON] -P localize_archive.cmake
foreach(var ARCHIVE LINKER OBJCOPY READELF AR)
  if(NOT ${var})
    message(FATAL_ERROR "localize_archive.cmake needs -D${var}=...")
  endif()
endforeach()

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(rc)
    message(FATAL_ERROR "${what} of ${ARCHIVE} failed: ${err}")
  endif()
endfunction()

if(STRIP_LTO)
  run("stripping the LTO sections" ${OBJCOPY} -R .gnu.lto_* -R .gnu.debuglto_* -N __gnu_lto_v1
      -N __gnu_lto_slim ${ARCHIVE})
endif()
get_filename_component(dir ${ARCHIVE} DIRECTORY)
set(object ${dir}/grainpack.o)
run("linking the objects" ${LINKER} -r --whole-archive ${ARCHIVE} -o ${object})
execute_process(COMMAND ${READELF} --wide --symbols ${object} OUTPUT_VARIABLE table RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "readelf of ${object} failed")
endif()
# "  12: 0000000000000000   42 FUNC    GLOBAL HIDDEN     3 front_init"
string(REGEX MATCHALL "GLOBAL +HIDDEN +[0-9]+ +[^ \n]+" hidden "${table}")
set(names "")
foreach(entry IN LISTS hidden)
  string(REGEX REPLACE ".* " "" name "${entry}")
  string(APPEND names "${name}\n")
endforeach()
file(WRITE ${object}.local "${names}")
run("localizing the internal symbols" ${OBJCOPY} --localize-symbols=${object}.local ${object})
file(REMOVE ${object}.local)
file(REMOVE ${ARCHIVE})
run("archiving" ${AR} qcs ${ARCHIVE} ${object})
file(REMOVE ${object})

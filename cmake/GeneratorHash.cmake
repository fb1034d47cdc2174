# Script mode (cmake -P): writes ${OUTPUT}, a header defining
# KANEGEN_GENERATOR_HASH as 16 hex digits of the SHA-256 of the generator's
# sources and templates (${INPUTS}, a ;-list, hashed in order, each preceded by
# its file name): a changed generator invalidates every JIT cache entry.
set(_all "")
foreach(f IN LISTS INPUTS)
  get_filename_component(_name "${f}" NAME)
  file(READ "${f}" _text)
  string(APPEND _all "${_name}\n${_text}\n")
endforeach()
string(SHA256 _sha "${_all}")
string(SUBSTRING "${_sha}" 0 16 _hash)
set(_content "// Generated at build time by cmake/GeneratorHash.cmake.\n#pragma once\n#define KANEGEN_GENERATOR_HASH \"${_hash}\"\n")
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" _old)
  if(_old STREQUAL _content)
    return()
  endif()
endif()
file(WRITE "${OUTPUT}" "${_content}")

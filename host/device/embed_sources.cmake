# The OpenCL C sources are embedded into the binary, so build/wavepath runs from anywhere; for
# kernel work without a rebuild, WAVEPATH_KERNEL_DIR=<repo>/kernels makes the host read them from
# disk instead (host/device/kernel_sources.cpp).
#
# wp_embed_sources(TARGET t FUNCTION f ROOT dir FILES a.cl b.h ...)
# Generates a C++ file defining `const std::vector<wp::EmbeddedFile>& wp::f()` with the text of
# each file (named by its path relative to ROOT) and adds it to target t.
set(WP_EMBED_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/embed_sources_run.cmake)

function(wp_embed_sources)
  cmake_parse_arguments(E "" "TARGET;FUNCTION;ROOT" "FILES" ${ARGN})
  set(out ${CMAKE_CURRENT_BINARY_DIR}/${E_FUNCTION}.cpp)
  set(deps)
  foreach(f ${E_FILES})
    list(APPEND deps ${E_ROOT}/${f})
  endforeach()
  string(REPLACE ";" "|" files_arg "${E_FILES}")
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DROOT=${E_ROOT} "-DFILES=${files_arg}" -DFUNCTION=${E_FUNCTION}
            -DOUT=${out} -P ${WP_EMBED_SCRIPT}
    DEPENDS ${deps} ${WP_EMBED_SCRIPT}
    COMMENT "Embedding ${E_FUNCTION} (${E_ROOT})"
    VERBATIM)
  target_sources(${E_TARGET} PRIVATE ${out})
endfunction()

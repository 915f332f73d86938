# The library's layers (docs/ARCHITECTURE.md, "Layers"): one static library per layer,
# posefilter_<layer> with the alias posefilter::<layer>, made by posefilter_add_layer in the
# layer's own src/<layer>/CMakeLists.txt from an explicit source list. A layer links only the
# layers it DEPENDS on (each below it), so its link line names nothing above it, and the
# umbrella posefilter::posefilter links them all.
#
# posefilter_layers.json (in the build folder) records every layer — its source folders, its
# public headers and the layers it may use — and tests/build/check_layers.py checks every
# #include of src/ and include/ against it (ctest build_layers; docs/ARCHITECTURE.md).

# posefilter_add_layer(<name> DIRS <src folders> [HEADERS <public headers>] [DEPENDS <layers>]
#                      [SOURCES <sources>] [NOT_BUILT])
#   DIRS     the folders under the project root whose files are the layer's (src/<layer>); a
#            file belongs to the layer of the longest folder that holds it
#   HEADERS  the layer's public headers, relative to the project root (include/posefilter/*.h)
#   DEPENDS  the layers it uses, each declared before it; on its link interface (a layer that is
#            not built, NOT_BUILT, is left off it but still allowed by the layer check)
#   SOURCES  its sources (.cc), relative to the calling folder or absolute
#   NOT_BUILT  declare the layer for the checker only (an option turned it off: POSEFILTER_HW)
function(posefilter_add_layer name)
  cmake_parse_arguments(arg "NOT_BUILT" "" "DIRS;HEADERS;DEPENDS;SOURCES" ${ARGN})
  foreach(dep IN LISTS arg_DEPENDS)
    get_property(declared GLOBAL PROPERTY POSEFILTER_LAYER_${dep}_DIRS SET)
    if(NOT declared)
      message(FATAL_ERROR "posefilter layer ${name}: DEPENDS ${dep}, which is not declared before it")
    endif()
  endforeach()
  set_property(GLOBAL APPEND PROPERTY POSEFILTER_LAYERS ${name})
  set_property(GLOBAL PROPERTY POSEFILTER_LAYER_${name}_DIRS ${arg_DIRS})
  set_property(GLOBAL PROPERTY POSEFILTER_LAYER_${name}_HEADERS ${arg_HEADERS})
  set_property(GLOBAL PROPERTY POSEFILTER_LAYER_${name}_DEPENDS ${arg_DEPENDS})
  if(arg_NOT_BUILT)
    set_property(GLOBAL PROPERTY POSEFILTER_LAYER_${name}_BUILT FALSE)
    return()
  endif()
  set_property(GLOBAL PROPERTY POSEFILTER_LAYER_${name}_BUILT TRUE)
  set(target posefilter_${name})
  add_library(${target} STATIC ${arg_SOURCES})
  add_library(posefilter::${name} ALIAS ${target})
  set_property(GLOBAL APPEND PROPERTY POSEFILTER_LAYER_TARGETS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name} POSITION_INDEPENDENT_CODE ON)
  # Every layer is compiled with the same flags and include folders, so that one precompiled
  # header (the core layer's) serves them all.
  target_include_directories(${target}
    PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
    PRIVATE ${PROJECT_SOURCE_DIR}/src ${PROJECT_BINARY_DIR}/generated ${POSEFILTER_HLS_TYPES_DIR})
  target_link_libraries(${target} PUBLIC Eigen3::Eigen PRIVATE OpenMP::OpenMP_CXX Threads::Threads)
  # The layers below: INTERFACE, since a static library links nothing itself; whatever links
  # this layer links them after it. (Linked PUBLIC, each layer's sources would wait for the
  # libraries below it to be built; they share the include folders, so they compile at once.)
  foreach(dep IN LISTS arg_DEPENDS)
    get_property(built GLOBAL PROPERTY POSEFILTER_LAYER_${dep}_BUILT)
    if(built)
      target_link_libraries(${target} INTERFACE posefilter::${dep})
    endif()
  endforeach()
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  # Unity build (POSEFILTER_UNITY_LIBRARY, the asan preset). CMake compiles a source with its own
  # COMPILE_OPTIONS or COMPILE_DEFINITIONS on its own (the cpu kernel per instruction set, the
  # fuzzed readers' coverage flags); a source that must not share a batch for another reason sets
  # SKIP_UNITY_BUILD_INCLUSION in its layer's CMakeLists.txt. File-local names (anonymous
  # namespaces) must differ between the sources of one layer.
  if(POSEFILTER_UNITY_LIBRARY)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
  endif()
  if(POSEFILTER_PCH)
    if(name STREQUAL "core")
      target_precompile_headers(${target} PRIVATE <Eigen/Core> <Eigen/Geometry> <nlohmann/json.hpp>
        ${POSEFILTER_PCH_STD})
    else()
      target_precompile_headers(${target} REUSE_FROM posefilter_core)
    endif()
  endif()
  # nlohmann-json is header-only; the core layer's precompiled header holds it, so every layer
  # compiles with its include folder.
  target_link_libraries(${target} PRIVATE nlohmann_json::nlohmann_json)
endfunction()

# Writes <build>/posefilter_layers.json: for each layer in declaration order, its folders,
# public headers, direct dependencies and whether this build has it.
function(posefilter_write_layers_json out)
  get_property(layers GLOBAL PROPERTY POSEFILTER_LAYERS)
  set(entries)
  foreach(layer IN LISTS layers)
    set(fields)
    foreach(field DIRS HEADERS DEPENDS)
      get_property(values GLOBAL PROPERTY POSEFILTER_LAYER_${layer}_${field})
      set(quoted)
      foreach(v IN LISTS values)
        list(APPEND quoted "\"${v}\"")
      endforeach()
      list(JOIN quoted ", " joined)
      string(TOLOWER ${field} key)
      list(APPEND fields "\"${key}\": [${joined}]")
    endforeach()
    get_property(built GLOBAL PROPERTY POSEFILTER_LAYER_${layer}_BUILT)
    if(built)
      list(APPEND fields "\"built\": true")
    else()
      list(APPEND fields "\"built\": false")
    endif()
    list(JOIN fields ",\n     " body)
    list(APPEND entries "    {\"name\": \"${layer}\",\n     ${body}}")
  endforeach()
  list(JOIN entries ",\n" text)
  file(CONFIGURE OUTPUT ${out} CONTENT "{\"layers\": [\n${text}\n]}\n" @ONLY)
endfunction()

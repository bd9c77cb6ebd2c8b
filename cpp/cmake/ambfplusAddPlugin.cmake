# ambfplus_add_plugin(target sources...): a plugin library (lib<target>.so) linked against
# ambfplus::ambfplus, its symbols hidden but the entry point AMBFPLUS_PLUGIN exports. Shared by
# the package's CMake config (third parties) and this tree's own plugins.
function(ambfplus_add_plugin target)
  add_library(${target} MODULE ${ARGN})
  target_link_libraries(${target} PRIVATE ambfplus::ambfplus)
  set_target_properties(${target} PROPERTIES
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
endfunction()

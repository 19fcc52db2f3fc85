# The rectum sample's anatomy (viscera-studio sample rectum): made by code into
# projects/rectum/anatomy/ (ignored by git), which projects/rectum imports, remeshes and meshes.
# Target viscera_rectum_anatomy (in `all`), defined once: by the studio's build, or by the samples
# package alone (packaging/samples) with its imported viscera-studio.
if(NOT TARGET viscera_rectum_anatomy)
  cmake_path(GET CMAKE_CURRENT_LIST_DIR PARENT_PATH viscera_anatomy_root) # the source tree
  set(VISCERA_RECTUM_ANATOMY_DIR ${viscera_anatomy_root}/projects/rectum/anatomy)
  set(VISCERA_RECTUM_ANATOMY)
  foreach(part mesorectum rectum pelvic_wall peritoneum)
    list(APPEND VISCERA_RECTUM_ANATOMY ${VISCERA_RECTUM_ANATOMY_DIR}/${part}.obj)
  endforeach()
  # COMMAND names the studio's target: its program, and a dependency on it when it is built here.
  add_custom_command(OUTPUT ${VISCERA_RECTUM_ANATOMY}
    COMMAND viscera-studio sample rectum -o ${VISCERA_RECTUM_ANATOMY_DIR}
    DEPENDS ${viscera_anatomy_root}/studio/bake/sample_anatomy.cpp
    COMMENT "Making the rectum sample's anatomy (projects/rectum/anatomy)" VERBATIM)
  add_custom_target(viscera_rectum_anatomy ALL DEPENDS ${VISCERA_RECTUM_ANATOMY})
endif()

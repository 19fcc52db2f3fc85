# Debian packages: viscera-player (the lean runtime and the console simulator), viscera-studio
# (authoring) and viscera-samples (the sample projects exported as cases). Made by
# scripts/package.sh: it builds the target viscera_samples (the exports), then runs
# `cpack -G DEB` in the build folder and checks what it made. packaging/samples/CMakeLists.txt
# includes it too, to make the samples package alone from a studio already built (a release
# signed with the publisher's key, without compiling).
#
# Every package carries /usr/share/doc/<package>/ (copyright, changelog.gz and its own guides:
# VISCERA_DOCS_<component>) and the man pages of its programs.

if(NOT DEFINED VISCERA_PACKAGES) # packaging/samples sets "samples"
  set(VISCERA_PACKAGES player studio samples)
endif()
cmake_path(GET CMAKE_CURRENT_LIST_DIR PARENT_PATH VISCERA_ROOT) # the source tree
set(VISCERA_PKG_OUT ${CMAKE_BINARY_DIR}/packaging)

# Man pages (version filled in) and the changelog, compressed without a timestamp (gzip -n).
# viscera-results.1 is written beside the results program (packaging/man/viscera-results.1).
set(VISCERA_MAN_PAGES viscera-player viscera-console-sim viscera-launcher viscera-results viscera-studio)
set(VISCERA_PKG_GZ)
foreach(page IN LISTS VISCERA_MAN_PAGES)
  set(VERSION ${PROJECT_VERSION})
  configure_file(${CMAKE_CURRENT_LIST_DIR}/man/${page}.1 ${VISCERA_PKG_OUT}/${page}.1 @ONLY)
  list(APPEND VISCERA_PKG_GZ ${VISCERA_PKG_OUT}/${page}.1.gz)
  add_custom_command(OUTPUT ${VISCERA_PKG_OUT}/${page}.1.gz
    COMMAND gzip -9nf -k ${VISCERA_PKG_OUT}/${page}.1
    DEPENDS ${VISCERA_PKG_OUT}/${page}.1 VERBATIM)
endforeach()
configure_file(${CMAKE_CURRENT_LIST_DIR}/doc/changelog.in ${VISCERA_PKG_OUT}/changelog @ONLY)
add_custom_command(OUTPUT ${VISCERA_PKG_OUT}/changelog.gz
  COMMAND gzip -9nf -k ${VISCERA_PKG_OUT}/changelog
  DEPENDS ${VISCERA_PKG_OUT}/changelog VERBATIM)
list(APPEND VISCERA_PKG_GZ ${VISCERA_PKG_OUT}/changelog.gz)
add_custom_target(viscera_package_docs ALL DEPENDS ${VISCERA_PKG_GZ})

# The docs of each package. The player's are for trainees and training sites (the developer
# README is not among them); the studio keeps the README, the reference of its command line and
# desktop application.
set(VISCERA_DOCS_player ${CMAKE_CURRENT_LIST_DIR}/doc/trainee-guide.md ${CMAKE_CURRENT_LIST_DIR}/doc/console-setup.md
    ${CMAKE_CURRENT_LIST_DIR}/vcase-spec.md ${CMAKE_CURRENT_LIST_DIR}/console-protocol.md)
set(VISCERA_DOCS_studio ${VISCERA_ROOT}/README.md ${CMAKE_CURRENT_LIST_DIR}/vcase-spec.md
    ${CMAKE_CURRENT_LIST_DIR}/console-protocol.md)
set(VISCERA_DOCS_samples ${CMAKE_CURRENT_LIST_DIR}/vcase-spec.md)
foreach(comp IN LISTS VISCERA_PACKAGES)
  install(FILES ${CMAKE_CURRENT_LIST_DIR}/doc/copyright ${VISCERA_PKG_OUT}/changelog.gz ${VISCERA_DOCS_${comp}}
          DESTINATION share/doc/viscera-${comp} COMPONENT ${comp})
endforeach()
install(FILES ${VISCERA_PKG_OUT}/viscera-player.1.gz ${VISCERA_PKG_OUT}/viscera-console-sim.1.gz
              ${VISCERA_PKG_OUT}/viscera-launcher.1.gz ${VISCERA_PKG_OUT}/viscera-results.1.gz
        DESTINATION share/man/man1 COMPONENT player)
install(FILES ${VISCERA_PKG_OUT}/viscera-studio.1.gz DESTINATION share/man/man1 COMPONENT studio)

# The sample cases: every project in projects/ exported by the studio just built, signed with
# VISCERA_SAMPLE_KEY (packaging/publisher_key.cmake). Not part of `all` (a minute of meshing);
# scripts/package.sh builds it before cpack.
file(GLOB VISCERA_SAMPLE_PROJECTS LIST_DIRECTORIES true CONFIGURE_DEPENDS ${VISCERA_ROOT}/projects/*)
set(VISCERA_SAMPLE_CASES)
foreach(dir IN LISTS VISCERA_SAMPLE_PROJECTS)
  if(NOT EXISTS ${dir}/project.json)
    continue()
  endif()
  get_filename_component(name ${dir} NAME)
  file(GLOB_RECURSE inputs CONFIGURE_DEPENDS ${dir}/*)
  set(out ${CMAKE_BINARY_DIR}/samples/${name}.vcase)
  add_custom_command(OUTPUT ${out}
    COMMAND $<TARGET_FILE:viscera-studio> export ${dir} -o ${out} --sign-key ${VISCERA_SAMPLE_KEY}
            --signer "${VISCERA_SAMPLE_SIGNER}"
    DEPENDS viscera-studio ${VISCERA_SAMPLE_KEY} ${inputs}
    COMMENT "Exporting the sample ${name}" VERBATIM)
  list(APPEND VISCERA_SAMPLE_CASES ${out})
endforeach()
add_custom_target(viscera_samples DEPENDS ${VISCERA_SAMPLE_CASES})
if(TARGET viscera_sample_key) # the test key (studio/cli); packaging/samples has a publisher key
  add_dependencies(viscera_samples viscera_sample_key)
endif()
include(${VISCERA_ROOT}/cmake/viscera_rectum_anatomy.cmake) # projects/rectum imports made anatomy
add_dependencies(viscera_samples viscera_rectum_anatomy)
install(FILES ${VISCERA_SAMPLE_CASES} DESTINATION share/viscera/samples COMPONENT samples OPTIONAL)
# The samples' recorded console sessions (`--device replay:FILE`): every projects/<project>/replays/*.csv
# in share/viscera/samples/replays/<project>/.
file(GLOB VISCERA_SAMPLE_REPLAYS CONFIGURE_DEPENDS ${VISCERA_ROOT}/projects/*/replays/*.csv)
foreach(replay IN LISTS VISCERA_SAMPLE_REPLAYS)
  get_filename_component(dir ${replay} DIRECTORY)
  get_filename_component(dir ${dir} DIRECTORY)
  get_filename_component(name ${dir} NAME)
  install(FILES ${replay} DESTINATION share/viscera/samples/replays/${name} COMPONENT samples)
endforeach()
# The samples' trust anchor: in a release (VISCERA_PUBLISHER_KEY) the publisher's public key,
# KEY.pub.pem under its own name (which names the signer), trusted by every player on the machine
# (the vendor trust folder). A test build installs none: its test key stays in the build folder,
# and a site that runs its samples adds the key itself (VISCERA_SAMPLES_TRUST_NOTE).
if(VISCERA_SAMPLE_TRUST_ANCHOR)
  install(FILES ${VISCERA_SAMPLE_TRUST_ANCHOR} DESTINATION share/viscera/trusted-publishers COMPONENT samples)
  get_filename_component(anchor ${VISCERA_SAMPLE_TRUST_ANCHOR} NAME)
  set(VISCERA_SAMPLES_TRUST_NOTE
"They are signed with the publisher's key, whose public half this
package installs as a trusted publisher for every player on the
machine: /usr/share/viscera/trusted-publishers/${anchor}")
else()
  set(VISCERA_SAMPLES_TRUST_NOTE
"They are signed with a test key and this package installs no trusted
publisher key: to run them, a site copies the signer's public key
(KEY.pub.pem) into /etc/viscera/trusted-publishers/ (owned by root,
mode 0644, the folder writable by no one else), or passes
--trust KEY.pub.pem to viscera-player.")
endif()

set(CPACK_PACKAGE_NAME "viscera")
set(CPACK_PACKAGE_VENDOR "Viscera")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "Viscera engineering <engineering@viscera.dev>")
set(CPACK_PACKAGING_INSTALL_PREFIX "/usr")
set(CPACK_GENERATOR "DEB")
set(CPACK_STRIP_FILES ON)
set(CPACK_COMPONENTS_ALL ${VISCERA_PACKAGES})
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION "science")
set(CPACK_DEBIAN_PACKAGE_PRIORITY "optional")
set(CPACK_DEBIAN_PACKAGE_HOMEPAGE "https://viscera.dev/")
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_DEBIAN_COMPRESSION_TYPE "xz")

set(CPACK_DEBIAN_PLAYER_PACKAGE_NAME "viscera-player")
# Mesa's DRI drivers (llvmpipe) for headless rendering where no GPU vendor supplies its own.
set(CPACK_DEBIAN_PLAYER_PACKAGE_RECOMMENDS "libgl1-mesa-dri")
set(CPACK_DEBIAN_PLAYER_DESCRIPTION
"surgical training simulator, trainee runtime
Viscera Player runs packaged surgical training cases (.vcase): soft
tissue simulated with XPBD and corotational FEM, grasping, energy
dissection, clips and suturing, driven by a two-master haptic console
with force feedback, a recorded replay, a script or the keyboard.
.
It builds only the subsystems a case declares, writes a session report
and plots, and renders headless through EGL (Mesa without a GPU). It
links no authoring library. Includes viscera-launcher, a desktop case
picker for trainees, and viscera-console-sim, a console simulator
speaking the console's UDP protocol.")

set(CPACK_DEBIAN_STUDIO_PACKAGE_NAME "viscera-studio")
set(CPACK_DEBIAN_STUDIO_PACKAGE_SUGGESTS "viscera-player")
set(CPACK_DEBIAN_STUDIO_DESCRIPTION
"surgical training simulator, case authoring studio
Viscera Studio is where medical and technical artists build training
cases for Viscera Player: tissue materials edited as stress-strain
curves, skeleton stiffness painting, procedural textures, light-sample
painting, instruments and their device mapping, meshing (CGAL) and
import of artists' meshes (assimp).
.
A Qt desktop application and a command line (export, import, texture,
replay) that produce the case packages the player runs.")

set(CPACK_DEBIAN_SAMPLES_PACKAGE_NAME "viscera-samples")
set(CPACK_DEBIAN_SAMPLES_PACKAGE_ARCHITECTURE "all")
set(CPACK_DEBIAN_SAMPLES_PACKAGE_SHLIBDEPS OFF)
set(CPACK_DEBIAN_SAMPLES_PACKAGE_DEPENDS "viscera-player (>= ${PROJECT_VERSION})")
set(CPACK_DEBIAN_SAMPLES_DESCRIPTION
"surgical training simulator, sample cases
Training cases for Viscera Player, in /usr/share/viscera/samples: a
tissue slab and an organ under gravity, a liver to palpate with a
probe, a rectal dissection (grasper, energy hook, clip applier) and an
intestinal anastomosis with a running suture; their recorded console
sessions in /usr/share/viscera/samples/replays.
.
${VISCERA_SAMPLES_TRUST_NOTE}")

include(CPack)

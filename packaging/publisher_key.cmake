# The key that signs the sample cases and the tests' cases (packaging/vcase-spec.md, "The
# samples"). Included by the top-level CMakeLists.txt and by packaging/samples/CMakeLists.txt.
#
# Release packages: the publisher's own key, VISCERA_PUBLISHER_KEY (a PEM private key with
# KEY.pub.pem beside it, kept outside the build folder). The samples package installs KEY.pub.pem
# as a trusted publisher (VISCERA_SAMPLE_TRUST_ANCHOR).
# Test builds (no VISCERA_PUBLISHER_KEY): a test key the studio makes in the build folder (target
# viscera_sample_key, studio/cli). The tests and scripts/package.sh use it from there; no package
# installs it, so the samples package of a test build has no trust anchor (a site adds its key:
# /etc/viscera/trusted-publishers or --trust).
#
# Sets VISCERA_SAMPLE_KEY, VISCERA_SAMPLE_PUBLIC_KEY, VISCERA_SAMPLE_SIGNER (the name the samples'
# signatures claim) and VISCERA_SAMPLE_TRUST_ANCHOR (the public key the samples package installs;
# empty in a test build).
set(VISCERA_PUBLISHER_KEY "" CACHE FILEPATH
    "Ed25519 private key (PEM, KEY.pub.pem beside it) that signs the sample cases of release packages; empty: a test key made in the build folder, installed by no package")
if(VISCERA_PUBLISHER_KEY)
  set(VISCERA_SAMPLE_KEY ${VISCERA_PUBLISHER_KEY})
  if(VISCERA_PUBLISHER_KEY MATCHES "\\.pem$")
    string(REGEX REPLACE "\\.pem$" ".pub.pem" VISCERA_SAMPLE_PUBLIC_KEY "${VISCERA_PUBLISHER_KEY}")
  else()
    set(VISCERA_SAMPLE_PUBLIC_KEY "${VISCERA_PUBLISHER_KEY}.pub.pem")
  endif()
  foreach(key IN ITEMS VISCERA_SAMPLE_KEY VISCERA_SAMPLE_PUBLIC_KEY)
    if(NOT IS_ABSOLUTE "${${key}}" OR NOT EXISTS "${${key}}" OR IS_DIRECTORY "${${key}}")
      message(FATAL_ERROR "VISCERA_PUBLISHER_KEY: '${${key}}' is not a key file (an absolute path to a PEM "
                          "private key with KEY.pub.pem beside it; viscera-studio keygen -o KEY.pem makes both)")
    endif()
  endforeach()
  cmake_path(IS_PREFIX CMAKE_BINARY_DIR "${VISCERA_SAMPLE_KEY}" NORMALIZE key_in_build)
  if(key_in_build)
    message(FATAL_ERROR "VISCERA_PUBLISHER_KEY: '${VISCERA_SAMPLE_KEY}' is in the build folder (a test key?): "
                        "a release's publisher key is kept outside it")
  endif()
  set(VISCERA_SAMPLE_SIGNER "Viscera samples")
  set(VISCERA_SAMPLE_TRUST_ANCHOR ${VISCERA_SAMPLE_PUBLIC_KEY})
else()
  set(VISCERA_SAMPLE_KEY ${CMAKE_BINARY_DIR}/keys/viscera-samples.pem)
  set(VISCERA_SAMPLE_PUBLIC_KEY ${CMAKE_BINARY_DIR}/keys/viscera-samples.pub.pem)
  set(VISCERA_SAMPLE_SIGNER "Viscera samples (test key)")
  set(VISCERA_SAMPLE_TRUST_ANCHOR "")
endif()

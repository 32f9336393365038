# The format SDK: the version header, what `cmake --install` puts where, the
# CMake package (find_package(casual3d)), the pkg-config file of the format
# library and the Debian package (cpack -G DEB). docs/SDK.md is the user's
# side of it.
#
# Installed layout (relative to the prefix, so the prefix can be moved):
#   bin/casual3d                        the program
#   share/casual3d/viewer/              its web viewer (wasm-viewer/)
#   include/casual3d/{format,encoder}/  public headers: #include <casual3d/format/x.h>
#   lib/libcasual3d_{format,encoder}.a  static libraries
#   lib/libcasual3d_base.a              what the encoder is built on (no headers)
#   lib/cmake/casual3d/                 casual3d::format, casual3d::encoder
#   lib/pkgconfig/casual3d-format.pc    the format library

include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# --- The version, from project(VERSION): format/version.h ---------------------
set(CASUAL3D_GENERATED_DIR ${PROJECT_BINARY_DIR}/generated)
configure_file(${PROJECT_SOURCE_DIR}/format/version.h.in
  ${CASUAL3D_GENERATED_DIR}/format/version.h @ONLY)
target_include_directories(casual3d_format PUBLIC
  $<BUILD_INTERFACE:${CASUAL3D_GENERATED_DIR}>
  $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
target_compile_features(casual3d_format INTERFACE cxx_std_17)

# --- Public headers -------------------------------------------------------------
# What a user of the libraries needs, and everything those headers include
# (cmake/Casual3dStageHeaders.cmake refuses a public header that includes a
# private one). Internal headers (threads, SIMD, SHA-256, levels of detail,
# tinygltf, test scenes) stay private.
set(CASUAL3D_PUBLIC_FORMAT_HEADERS
  format/color_atlas.h
  format/colour_atlas.h
  format/equirect.h
  format/file_source.h
  format/image.h
  format/json.h
  format/manifest.h
  format/mesh.h
  format/mesh_builder.h
  format/mesh_simplify.h
  format/package_reader.h
  format/reader_checks.h
  format/single_file.h
  format/status.h
  format/tile_codec.h
  format/tile_image_format.h
  format/two_layer.h
  format/version.h
  format/view_hints.h
)
set(CASUAL3D_PUBLIC_ENCODER_HEADERS
  encoder/gltf_export.h
  encoder/master_file.h
  encoder/package_writer.h
  encoder/tile_image_codec.h
  encoder/webp_codec.h
)
set(CASUAL3D_SDK_LIBRARIES casual3d_format)
set(CASUAL3D_PUBLIC_HEADERS ${CASUAL3D_PUBLIC_FORMAT_HEADERS})
if(TARGET casual3d_encoder)
  list(APPEND CASUAL3D_SDK_LIBRARIES casual3d_encoder)
  list(APPEND CASUAL3D_PUBLIC_HEADERS ${CASUAL3D_PUBLIC_ENCODER_HEADERS})
endif()

set(staged_include_dir ${PROJECT_BINARY_DIR}/sdk/include)
set(staged_headers)
set(header_sources)
foreach(header ${CASUAL3D_PUBLIC_HEADERS})
  list(APPEND staged_headers ${staged_include_dir}/casual3d/${header})
  if(EXISTS ${PROJECT_SOURCE_DIR}/${header})
    list(APPEND header_sources ${PROJECT_SOURCE_DIR}/${header})
  else()
    list(APPEND header_sources ${CASUAL3D_GENERATED_DIR}/${header})
  endif()
endforeach()
add_custom_command(
  OUTPUT ${staged_headers}
  COMMAND ${CMAKE_COMMAND} -E rm -rf ${staged_include_dir}
  COMMAND ${CMAKE_COMMAND} "-DHEADERS=${CASUAL3D_PUBLIC_HEADERS}"
    "-DSEARCH_DIRS=${PROJECT_SOURCE_DIR};${CASUAL3D_GENERATED_DIR}"
    -DOUTPUT_DIR=${staged_include_dir}
    -P ${PROJECT_SOURCE_DIR}/cmake/Casual3dStageHeaders.cmake
  DEPENDS ${header_sources} ${PROJECT_SOURCE_DIR}/cmake/Casual3dStageHeaders.cmake
  COMMENT "Public headers for installation"
  VERBATIM)
add_custom_target(casual3d_sdk_headers ALL DEPENDS ${staged_headers})
install(DIRECTORY ${staged_include_dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})

# --- Libraries and the CMake package ---------------------------------------------
set(CASUAL3D_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/casual3d)
set(CASUAL3D_SDK_COMPONENTS)  # casual3dConfig.cmake.in
foreach(lib ${CASUAL3D_SDK_LIBRARIES})
  string(REPLACE "casual3d_" "" export_name ${lib})
  list(APPEND CASUAL3D_SDK_COMPONENTS ${export_name})
  set_target_properties(${lib} PROPERTIES EXPORT_NAME ${export_name})
  # The names users write, also inside this tree.
  add_library(casual3d::${export_name} ALIAS ${lib})
endforeach()
install(TARGETS ${CASUAL3D_SDK_LIBRARIES} EXPORT casual3dTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
# The static encoder library links casual3d_base (base/: threads, atomic
# files, OpenEXR), which has no public headers and is no component of its own;
# it is installed and exported for the encoder's link line.
if(TARGET casual3d_encoder)
  set_target_properties(casual3d_base PROPERTIES EXPORT_NAME base)
  install(TARGETS casual3d_base EXPORT casual3dTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
endif()
install(EXPORT casual3dTargets NAMESPACE casual3d:: DESTINATION ${CASUAL3D_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/casual3dConfig.cmake.in
  ${PROJECT_BINARY_DIR}/sdk/casual3dConfig.cmake
  INSTALL_DESTINATION ${CASUAL3D_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/sdk/casual3dConfigVersion.cmake
  COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/sdk/casual3dConfig.cmake
  ${PROJECT_BINARY_DIR}/sdk/casual3dConfigVersion.cmake
  DESTINATION ${CASUAL3D_CMAKE_DIR})

# --- pkg-config: the format library -----------------------------------------------
# The prefix is found from the .pc file's own folder (${pcfiledir}).
set(pc_dir ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
file(RELATIVE_PATH CASUAL3D_PC_PREFIX_FROM_PCFILEDIR /prefix/${pc_dir} /prefix)
string(REGEX REPLACE "/$" "" CASUAL3D_PC_PREFIX_FROM_PCFILEDIR ${CASUAL3D_PC_PREFIX_FROM_PCFILEDIR})
configure_file(${PROJECT_SOURCE_DIR}/cmake/casual3d-format.pc.in
  ${PROJECT_BINARY_DIR}/sdk/casual3d-format.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/sdk/casual3d-format.pc DESTINATION ${pc_dir})

# --- The program ---------------------------------------------------------------
# It finds its viewer at ${CMAKE_INSTALL_DATADIR}/casual3d/viewer relative to
# its own folder (cli/CMakeLists.txt, cli/viewer_assets.h); wasm-viewer/
# installs the viewer there.
if(TARGET casual3d)
  install(TARGETS casual3d RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

# --- Debian package: cpack -G DEB -------------------------------------------------
set(CASUAL3D_PACKAGE_CONTACT "casual3d maintainers" CACHE STRING
  "Maintainer field of the Debian package")
set(CPACK_PACKAGE_NAME casual3d)
set(CPACK_PACKAGE_VENDOR casual3d)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
  "casual 3D photography: 3D photos from hand-held photos, their format SDK and web viewer")
set(CPACK_PACKAGE_CONTACT ${CASUAL3D_PACKAGE_CONTACT})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
# Runtime dependencies from the libraries the binaries link (dpkg-shlibdeps).
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
  "Turns a few dozen hand-held photos taken from one spot into a two-layer 3D photo\n\
viewable with motion parallax in a web browser (the casual3d program and its\n\
web viewer), with the C++ format and encoder libraries, headers, CMake package\n\
and pkg-config file to read and write 3D photos from other programs.")
include(CPack)

# --- Tests: the installed tree, its consumers and the Debian package -------------
if(CASUAL3D_BUILD_TESTS)
  add_subdirectory(${PROJECT_SOURCE_DIR}/tests/sdk ${PROJECT_BINARY_DIR}/tests/sdk)
endif()

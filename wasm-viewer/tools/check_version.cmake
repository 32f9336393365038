# ctest viewer_npm_version_test: the npm package's version is the project's.
#   cmake -DPACKAGE_JSON=wasm-viewer/package.json -DEXPECTED=<PROJECT_VERSION> -P check_version.cmake
file(READ "${PACKAGE_JSON}" json)
string(JSON version ERROR_VARIABLE error GET "${json}" version)
if(error)
  message(FATAL_ERROR "${PACKAGE_JSON}: no \"version\" (${error})")
endif()
if(NOT version STREQUAL EXPECTED)
  message(FATAL_ERROR "${PACKAGE_JSON}: version ${version}, but project(casual3d VERSION ${EXPECTED}); "
                      "set the same version in both")
endif()
message(STATUS "${PACKAGE_JSON}: version ${version} = project version")

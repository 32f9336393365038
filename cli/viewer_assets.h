#pragma once

// The built web viewer (wasm-viewer/) and the page that embeds it, so that the
// output folder of `casual3d encode` and `casual3d reconstruct` is deployable to
// any static host as is, and `casual3d view` can serve it.
//
// Where the viewer files are found, first match wins:
//   1. $CASUAL3D_VIEWER_DIR (a folder holding casual3d-viewer.js and friends);
//   2. <folder of the casual3d binary>/../share/casual3d/viewer (the install
//      layout; relative, so an installed prefix can be moved);
//   3. <folder of the casual3d binary>/../wasm-viewer/dist (the build tree's
//      layout), so a freshly built, uninstalled binary works too.
// Both relative paths come from CMake (cli/CMakeLists.txt).

#include <filesystem>
#include <string>
#include <vector>

namespace casual3d::cli {

// Name of the folder inside a package that holds the viewer files.
constexpr const char* kViewerSubdir = "viewer";

// Returns the folder holding the built viewer files (see above). Throws
// std::runtime_error naming the places searched when none holds the viewer.
std::filesystem::path FindViewerDir();

// The index.html of a package folder: one <casual3d-viewer> element showing
// manifest.json, loading the viewer from `viewer_url_prefix` (e.g. "viewer/").
// `capture_advice` (pipeline::PipelineReport::capture_advice: a description,
// then warnings), when not empty, fills the element's info panel ("About
// this capture", its slot "info"), open at load when there are warnings.
std::string ViewerPageHtml(const std::string& title, const std::string& viewer_url_prefix,
                           const std::vector<std::string>& capture_advice = {});

// Copies the viewer files into <package_dir>/viewer/ and writes
// <package_dir>/index.html (with `capture_advice` as above), titled `title`
// (empty: the folder's name). Files are written
// under temporary names and renamed, so an interrupted run never leaves a
// half-written file. Throws std::runtime_error naming the file on failure
// (package_dir must exist).
void WriteViewerPage(const std::filesystem::path& package_dir,
                     const std::vector<std::string>& capture_advice = {},
                     const std::string& title = "");

// The name of `folder` as a person reads it: its last component, ignoring a
// trailing separator and "." ("out/fern/" -> "fern").
std::string FolderName(const std::filesystem::path& folder);

}  // namespace casual3d::cli

#include "cli/viewer_assets.h"

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "base/atomic_file.h"
#include "reconstruct/util/html.h"

namespace casual3d::cli {
namespace fs = std::filesystem;

namespace {

// The file whose presence marks a folder as holding the built viewer.
constexpr const char* kViewerEntry = "casual3d-viewer.js";

bool HoldsViewer(const fs::path& dir) {
  std::error_code ec;
  return fs::is_regular_file(dir / kViewerEntry, ec);
}

fs::path ExecutableDir() {
  std::vector<char> buffer(4096);
  const ssize_t n = readlink("/proc/self/exe", buffer.data(), buffer.size() - 1);
  if (n <= 0) return {};
  return fs::path(std::string(buffer.data(), static_cast<size_t>(n))).parent_path();
}

// Writes `bytes` to `path` atomically (base/atomic_file.h).
void WriteFileAtomically(const fs::path& path, const std::string& bytes) {
  const Status written = base::WriteFileAtomic(path.string(), bytes);
  if (!written.ok()) throw std::runtime_error(written.message());
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot read the viewer file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

fs::path FindViewerDir() {
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("CASUAL3D_VIEWER_DIR"); env && *env)
    candidates.emplace_back(env);
  const fs::path exe_dir = ExecutableDir();
  if (!exe_dir.empty()) {
    candidates.push_back(exe_dir / CASUAL3D_VIEWER_INSTALLED_RELDIR);
    candidates.push_back(exe_dir / CASUAL3D_VIEWER_BUILD_RELDIR);
  }
  std::string searched;
  for (const fs::path& dir : candidates) {
    if (HoldsViewer(dir)) return dir.lexically_normal();
    searched += (searched.empty() ? "" : ", ") + dir.lexically_normal().string();
  }
  throw std::runtime_error("the web viewer files (" + std::string(kViewerEntry) + ") are not in " +
                           searched + "; build the wasm-viewer target or set CASUAL3D_VIEWER_DIR");
}

std::string ViewerPageHtml(const std::string& title, const std::string& viewer_url_prefix,
                           const std::vector<std::string>& capture_advice) {
  const std::string t = util::HtmlEscape(title);
  const std::string p = util::HtmlEscape(viewer_url_prefix);
  // The capture's advice in the element's info slot: the page's own data,
  // so the package format stays as it is.
  std::string info;
  if (!capture_advice.empty()) {
    info = "<div slot=\"info\">\n<h2>About this capture</h2>\n";
    for (size_t k = 0; k < capture_advice.size(); ++k)
      info += std::string(k == 0 ? "<p>" : "<p class=\"warning\">") +
              util::HtmlEscape(capture_advice[k]) + "</p>\n";
    info += "</div>\n";
  }
  const std::string open = capture_advice.size() > 1 ? " info-open" : "";
  return "<!DOCTYPE html>\n"
         "<html lang=\"en\">\n"
         "<head>\n"
         "<meta charset=\"utf-8\">\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
         "<title>" +
         t +
         "</title>\n"
         "<script type=\"module\" src=\"" +
         p + kViewerEntry +
         "\"></script>\n"
         "<style>html,body{margin:0;height:100%;background:#000}"
         "casual3d-viewer{display:block;width:100%;height:100%}" +
         (info.empty() ? "" : "casual3d-viewer h2{font-size:14px;margin:0 0 6px}"
                              "casual3d-viewer p{margin:0 0 6px}casual3d-viewer .warning{color:#ffd166}") +
         "</style>\n"
         "</head>\n"
         "<body>\n"
         "<casual3d-viewer src=\"manifest.json\" controls" +
         open + ">" + (info.empty() ? "" : "\n" + info) +
         "</casual3d-viewer>\n"
         "</body>\n"
         "</html>\n";
}

std::string FolderName(const fs::path& folder) {
  const fs::path normal = fs::absolute(folder).lexically_normal();
  const std::string name = normal.filename().string();
  return name.empty() ? normal.parent_path().filename().string() : name;
}

void WriteViewerPage(const fs::path& package_dir, const std::vector<std::string>& capture_advice,
                     const std::string& title) {
  std::error_code ec;
  if (!fs::is_directory(package_dir, ec)) {
    throw std::runtime_error(package_dir.string() + ": not a folder; write the package first");
  }
  const fs::path source = FindViewerDir();
  const fs::path target = package_dir / kViewerSubdir;
  fs::create_directories(target, ec);
  if (ec) throw std::runtime_error(target.string() + ": cannot create the folder: " + ec.message());
  for (const fs::directory_entry& entry : fs::directory_iterator(source, ec)) {
    if (!entry.is_regular_file()) continue;
    WriteFileAtomically(target / entry.path().filename(), ReadFile(entry.path()));
  }
  if (ec)
    throw std::runtime_error(source.string() + ": cannot list the viewer files: " + ec.message());
  const std::string name = title.empty() ? FolderName(package_dir) : title;
  WriteFileAtomically(package_dir / "index.html",
                      ViewerPageHtml(name + " - casual3d", "viewer/", capture_advice));
}

}  // namespace casual3d::cli

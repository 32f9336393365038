// `casual3d view <package> [--port N]`: serves a package folder and the web
// viewer on 127.0.0.1 with a small static HTTP/1.1 server (cli/static_server.h)
// and prints the address.

#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "cli/command.h"
#include "cli/static_server.h"
#include "cli/viewer_assets.h"

namespace casual3d::cli {
namespace fs = std::filesystem;
namespace {

struct ViewOptions {
  std::string package;  // Package folder (holds manifest.json).
  int port = 8080;      // TCP port on 127.0.0.1; 0 picks a free port.
};

void RunView(const ViewOptions& options) {
  std::error_code ec;
  const fs::path package_dir = fs::absolute(options.package).lexically_normal();
  if (!fs::is_directory(package_dir, ec)) {
    throw std::runtime_error(options.package +
                             ": not a folder; pass a package folder written by casual3d encode");
  }
  if (!fs::is_regular_file(package_dir / "manifest.json", ec)) {
    throw std::runtime_error(
        options.package + ": no manifest.json; pass a package folder written by casual3d encode");
  }
  if (options.port < 0 || options.port > 65535) {
    throw std::runtime_error("--port " + std::to_string(options.port) + " is outside 0..65535");
  }
  const fs::path viewer_dir = FindViewerDir();

  StaticSite site;
  site.root = package_dir;
  site.mount = kViewerSubdir;  // The viewer of this binary first.
  site.mount_dir = viewer_dir;
  site.fallback_index_html = ViewerPageHtml(package_dir.filename().string() + " - casual3d",
                                            std::string(kViewerSubdir) + "/");
  site.log_name = "view";
  StaticServer server(std::move(site));
  if (const Status st = server.Listen(options.port); !st.ok()) {
    throw std::runtime_error("--port " + std::to_string(options.port) +
                             ": cannot listen on 127.0.0.1 (" + st.message() +
                             "); pick another port or --port 0");
  }
  std::printf("casual3d: serving %s at http://127.0.0.1:%d/ (Ctrl-C to stop)\n",
              package_dir.c_str(), server.port());
  std::fflush(stdout);
  if (const Status st = server.Serve(); !st.ok()) throw std::runtime_error(st.message());
}

}  // namespace

void AddViewCommand(CLI::App& app) {
  auto options = std::make_shared<ViewOptions>();
  CLI::App* cmd = app.add_subcommand(
      "view", "Serve a package and the web viewer on 127.0.0.1 and print the address");
  cmd->add_option("package", options->package, "Package folder (holds manifest.json)")->required();
  cmd->add_option("--port", options->port, "TCP port on 127.0.0.1 (0: any free port)")
      ->capture_default_str();
  cmd->callback([options] { RunView(*options); });
}

}  // namespace casual3d::cli

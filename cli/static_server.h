#pragma once

// A small static HTTP/1.1 file server on 127.0.0.1 (what `casual3d view`
// serves a package and the viewer with).
//
// Deliberately minimal and safe: GET and HEAD only (with single byte ranges,
// so that the viewer reads a .c3d file level by level), one request per
// connection, bounded request size, socket timeouts, a cap on concurrent
// connections, and no path can leave the served folders (".." segments,
// encoded or not, are refused and symbolic links are resolved before the
// check). Every response carries the cross-origin isolation headers the
// viewer's threaded build needs.

#include <atomic>
#include <filesystem>
#include <memory>
#include <string>

#include "format/status.h"

namespace casual3d::cli {

// What a StaticServer serves.
struct StaticSite {
  std::filesystem::path root;  // Served at "/"; "/" itself is root/index.html.
  // When not empty: "/<mount>/<path>" is looked up in mount_dir first, then
  // in root (so that a folder's own copy is the fallback).
  std::string mount;
  std::filesystem::path mount_dir;
  // When not empty: served as "/" and "/index.html" if root holds no index.html.
  std::string fallback_index_html;
  // Each request is logged (util::LogInfo) as "<log_name>: GET /path".
  std::string log_name = "static";
};

// The Content-Type of a file by its extension (case-insensitive): the tile
// image formats (format/tile_image_format.h) and the usual web types;
// application/octet-stream for anything else.
std::string MimeType(const std::filesystem::path& path);

class StaticServer {
 public:
  explicit StaticServer(StaticSite site);
  ~StaticServer();  // Closes the listening socket (call Stop and wait for Serve first).
  StaticServer(const StaticServer&) = delete;
  StaticServer& operator=(const StaticServer&) = delete;

  // Listens on 127.0.0.1:`port` (0: a free port, see port()). An IoError
  // names the reason (e.g. "Address already in use").
  Status Listen(int port);
  // The port listened on (after Listen).
  int port() const { return port_; }
  // Accepts connections, each answered on its own thread, until Stop();
  // returns OK then, or an IoError if accepting fails for another reason.
  Status Serve();
  // Makes Serve return; callable from another thread.
  void Stop();

 private:
  struct Shared;  // The site and the connection count, shared with the threads.
  std::shared_ptr<Shared> shared_;
  int listen_fd_ = -1;
  int port_ = 0;
  std::atomic<bool> stopping_{false};
};

}  // namespace casual3d::cli

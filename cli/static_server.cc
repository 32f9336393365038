// The static file server of cli/static_server.h.

#include "cli/static_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include "format/tile_image_format.h"
#include "reconstruct/util/log.h"

namespace casual3d::cli {
namespace fs = std::filesystem;

std::string MimeType(const fs::path& path) {
  static const std::pair<const char*, const char*> kTypes[] = {
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".json", "application/json"},
      {".wasm", "application/wasm"},
      {".png", "image/png"},
      {".jpg", "image/jpeg"},
      {".jpeg", "image/jpeg"},
      {".css", "text/css; charset=utf-8"},
      {".ts", "text/plain; charset=utf-8"},
      {".txt", "text/plain; charset=utf-8"},
      {".md", "text/plain; charset=utf-8"},
      {".glb", "model/gltf-binary"},
      {".gltf", "model/gltf+json"},
      {".exr", "image/x-exr"},
      {".svg", "image/svg+xml"},
  };
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (const TileImageFormat* tiles = TileImageFormatByExtension(ext)) return tiles->mime_type;
  for (const auto& [e, type] : kTypes) {
    if (ext == e) return type;
  }
  return "application/octet-stream";
}


struct StaticServer::Shared {
  StaticSite site;
  std::atomic<int> connections{0};
};

namespace {

constexpr size_t kMaxRequestBytes = 16 * 1024;  // Request line plus headers.
constexpr size_t kMaxPathBytes = 2048;
constexpr int kMaxConnections = 64;
constexpr int kSocketTimeoutSeconds = 10;

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Decodes %XX escapes; nullopt on a malformed escape or a decoded NUL.
std::optional<std::string> PercentDecode(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '%') {
      out += s[i];
      continue;
    }
    if (i + 2 >= s.size()) return std::nullopt;
    const int hi = HexValue(s[i + 1]), lo = HexValue(s[i + 2]);
    if (hi < 0 || lo < 0 || (hi == 0 && lo == 0)) return std::nullopt;
    out += static_cast<char>(hi * 16 + lo);
    i += 2;
  }
  return out;
}

// Splits a decoded URL path into safe segments; nullopt if any segment is "..",
// ".", contains a backslash or a NUL, or the path is not absolute.
std::optional<std::vector<std::string>> SafeSegments(const std::string& path) {
  if (path.empty() || path[0] != '/') return std::nullopt;
  std::vector<std::string> segments;
  size_t start = 1;
  while (start <= path.size()) {
    size_t end = path.find('/', start);
    if (end == std::string::npos) end = path.size();
    const std::string seg = path.substr(start, end - start);
    if (seg == ".." || seg == "." || seg.find('\\') != std::string::npos ||
        seg.find('\0') != std::string::npos) {
      return std::nullopt;
    }
    if (!seg.empty()) segments.push_back(seg);
    start = end + 1;
  }
  return segments;
}

// Resolves `segments` under `root`; nullopt unless the result is a regular file
// whose real path (symbolic links resolved) is inside the real `root`.
std::optional<fs::path> ResolveUnder(const fs::path& root, const std::vector<std::string>& segments,
                                     size_t first) {
  fs::path p = root;
  for (size_t i = first; i < segments.size(); ++i) p /= segments[i];
  std::error_code ec;
  const fs::path real_root = fs::canonical(root, ec);
  if (ec) return std::nullopt;
  const fs::path real = fs::canonical(p, ec);
  if (ec || !fs::is_regular_file(real, ec)) return std::nullopt;
  const std::string r = real_root.string(), f = real.string();
  if (f.size() <= r.size() || f.compare(0, r.size(), r) != 0 || f[r.size()] != '/')
    return std::nullopt;
  return real;
}

bool SendAll(int fd, const char* data, size_t size) {
  while (size > 0) {
    const ssize_t n = send(fd, data, size, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    size -= static_cast<size_t>(n);
  }
  return true;
}

void SendSimple(int fd, int code, const char* reason, const std::string& body) {
  const std::string head = "HTTP/1.1 " + std::to_string(code) + " " + reason +
                           "\r\nContent-Type: text/plain; charset=utf-8\r\nContent-Length: " +
                           std::to_string(body.size()) + "\r\nConnection: close\r\n\r\n";
  SendAll(fd, head.data(), head.size()) && SendAll(fd, body.data(), body.size());
}

// The head of a response with a body of `length` bytes; `status` is e.g.
// "200 OK", `extra` more header lines (each ending in \r\n).
std::string ResponseHeader(const char* status, const std::string& type, uintmax_t length,
                           const std::string& extra = "") {
  return std::string("HTTP/1.1 ") + status + "\r\nContent-Type: " + type +
         "\r\nContent-Length: " + std::to_string(length) + "\r\n" + extra +
         "Accept-Ranges: bytes\r\nCache-Control: no-cache\r\nX-Content-Type-Options: nosniff\r\n"
         "Access-Control-Allow-Origin: *\r\n"
         // Cross-origin isolation lets the viewer use its threaded wasm build.
         "Cross-Origin-Opener-Policy: same-origin\r\nCross-Origin-Embedder-Policy: require-corp\r\n"
         "Cross-Origin-Resource-Policy: cross-origin\r\nConnection: close\r\n\r\n";
}

std::string OkHeader(const std::string& type, uintmax_t length) {
  return ResponseHeader("200 OK", type, length);
}

// The value of header `name` (lower case) in a request's head, or "".
std::string HeaderValue(const std::string& request, const std::string& name) {
  size_t line = request.find("\r\n");
  while (line != std::string::npos) {
    const size_t start = line + 2;
    const size_t end = request.find("\r\n", start);
    if (end == std::string::npos || end == start) break;
    const size_t colon = request.find(':', start);
    if (colon != std::string::npos && colon < end && colon - start == name.size()) {
      std::string key = request.substr(start, colon - start);
      for (char& c : key) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      if (key == name) {
        size_t a = colon + 1, b = end;
        while (a < b && (request[a] == ' ' || request[a] == '\t')) ++a;
        while (b > a && (request[b - 1] == ' ' || request[b - 1] == '\t')) --b;
        return request.substr(a, b - a);
      }
    }
    line = end;
  }
  return "";
}

// A byte range of a file (RFC 9110 Sec. 14): [first, last], inclusive.
struct ByteRange {
  uintmax_t first = 0;
  uintmax_t last = 0;
};

// Parses a Range header's value for a file of `size` bytes. nullopt: no range
// to honour (absent, another unit, several ranges or malformed: the whole file
// is sent, as the RFC allows); a range with first > last: unsatisfiable (416).
std::optional<ByteRange> ParseRange(const std::string& value, uintmax_t size) {
  const std::string unit = "bytes=";
  if (value.compare(0, unit.size(), unit) != 0) return std::nullopt;
  const std::string spec = value.substr(unit.size());
  const size_t dash = spec.find('-');
  if (dash == std::string::npos || spec.find(',') != std::string::npos) return std::nullopt;
  const std::string a = spec.substr(0, dash), b = spec.substr(dash + 1);
  auto number = [](const std::string& t) -> std::optional<uintmax_t> {
    if (t.empty() || t.size() > 19 || t.find_first_not_of("0123456789") != std::string::npos)
      return std::nullopt;
    return std::stoull(t);
  };
  const ByteRange unsatisfiable{1, 0};
  if (a.empty()) {  // "-n": the last n bytes.
    const std::optional<uintmax_t> n = number(b);
    if (!n) return std::nullopt;
    if (*n == 0 || size == 0) return unsatisfiable;
    return ByteRange{size - std::min(*n, size), size - 1};
  }
  const std::optional<uintmax_t> first = number(a);
  const std::optional<uintmax_t> last = b.empty() ? std::optional<uintmax_t>(UINTMAX_MAX) : number(b);
  if (!first || !last || *last < *first) return std::nullopt;
  if (*first >= size) return unsatisfiable;
  return ByteRange{*first, std::min(*last, size - 1)};
}

// Sends a file, or the byte range `range` (a Range header's value) of it.
void SendFile(int fd, const fs::path& path, bool head_only, const std::string& range) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  const uintmax_t size = fs::file_size(path, ec);
  if (!in || ec) {
    SendSimple(fd, 404, "Not Found", "not found\n");
    return;
  }
  const std::optional<ByteRange> part = range.empty() ? std::nullopt : ParseRange(range, size);
  std::string head;
  uintmax_t left = size;
  if (part && part->first > part->last) {
    const std::string body = "range not satisfiable\n";
    head = ResponseHeader("416 Range Not Satisfiable", "text/plain; charset=utf-8", body.size(),
                          "Content-Range: bytes */" + std::to_string(size) + "\r\n");
    SendAll(fd, head.data(), head.size()) && !head_only && SendAll(fd, body.data(), body.size());
    return;
  } else if (part) {
    left = part->last - part->first + 1;
    head = ResponseHeader("206 Partial Content", MimeType(path), left,
                          "Content-Range: bytes " + std::to_string(part->first) + "-" +
                              std::to_string(part->last) + "/" + std::to_string(size) + "\r\n");
    in.seekg(static_cast<std::streamoff>(part->first));
  } else {
    head = OkHeader(MimeType(path), size);
  }
  if (!SendAll(fd, head.data(), head.size()) || head_only) return;
  std::vector<char> chunk(1 << 16);
  while (left > 0 && in) {
    in.read(chunk.data(), static_cast<std::streamsize>(std::min<uintmax_t>(chunk.size(), left)));
    const std::streamsize n = in.gcount();
    if (n <= 0 || !SendAll(fd, chunk.data(), static_cast<size_t>(n))) return;
    left -= static_cast<uintmax_t>(n);
  }
}

// Answers the one request of connection `fd`.
void HandleConnection(const StaticSite& site, int fd) {
  std::string request;
  char buffer[4096];
  while (request.find("\r\n\r\n") == std::string::npos) {
    if (request.size() > kMaxRequestBytes) {
      SendSimple(fd, 431, "Request Header Fields Too Large", "request too large\n");
      return;
    }
    const ssize_t n = recv(fd, buffer, sizeof(buffer), 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // Closed or timed out.
    request.append(buffer, static_cast<size_t>(n));
  }
  const size_t line_end = request.find("\r\n");
  const std::string line = request.substr(0, line_end);
  const size_t sp1 = line.find(' ');
  const size_t sp2 = sp1 == std::string::npos ? sp1 : line.find(' ', sp1 + 1);
  if (sp2 == std::string::npos) {
    SendSimple(fd, 400, "Bad Request", "malformed request line\n");
    return;
  }
  const std::string method = line.substr(0, sp1);
  std::string target = line.substr(sp1 + 1, sp2 - sp1 - 1);
  if (method != "GET" && method != "HEAD") {
    SendSimple(fd, 405, "Method Not Allowed", "only GET and HEAD\n");
    return;
  }
  if (target.size() > kMaxPathBytes) {
    SendSimple(fd, 414, "URI Too Long", "path too long\n");
    return;
  }
  target = target.substr(0, target.find_first_of("?#"));
  const std::optional<std::string> decoded = PercentDecode(target);
  const std::optional<std::vector<std::string>> segments =
      decoded ? SafeSegments(*decoded) : std::nullopt;
  if (!segments) {
    SendSimple(fd, 400, "Bad Request", "path not allowed\n");
    return;
  }
  util::LogInfo(site.log_name + ": " + method + " " + target);
  const bool head_only = method == "HEAD";

  if (!site.fallback_index_html.empty() &&
      (segments->empty() || (segments->size() == 1 && (*segments)[0] == "index.html"))) {
    if (!ResolveUnder(site.root, {"index.html"}, 0)) {
      const std::string& html = site.fallback_index_html;
      const std::string head = OkHeader("text/html; charset=utf-8", html.size());
      SendAll(fd, head.data(), head.size()) && !head_only && SendAll(fd, html.data(), html.size());
      return;
    }
  }
  std::optional<fs::path> file;
  if (!site.mount.empty() && segments->size() >= 2 && (*segments)[0] == site.mount) {
    file = ResolveUnder(site.mount_dir, *segments, 1);
  }
  if (!file) file = ResolveUnder(site.root, *segments, 0);
  if (segments->empty()) file = ResolveUnder(site.root, {"index.html"}, 0);
  if (!file) {
    SendSimple(fd, 404, "Not Found", "not found\n");
    return;
  }
  SendFile(fd, *file, head_only,
           HeaderValue(request.substr(0, request.find("\r\n\r\n") + 2), "range"));
}

}  // namespace

StaticServer::StaticServer(StaticSite site) : shared_(std::make_shared<Shared>()) {
  shared_->site = std::move(site);
}

StaticServer::~StaticServer() {
  if (listen_fd_ >= 0) close(listen_fd_);
}

Status StaticServer::Listen(int port) {
  if (port < 0 || port > 65535)
    return InvalidArgument("port " + std::to_string(port) + " is outside 0..65535");
  listen_fd_ = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0) return IoError(std::string("cannot create a socket: ") + std::strerror(errno));
  const int one = 1;
  setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);  // Never exposed beyond this machine.
  addr.sin_port = htons(static_cast<uint16_t>(port));
  if (bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 ||
      listen(listen_fd_, 64) != 0) {
    const std::string reason = std::strerror(errno);
    close(listen_fd_);
    listen_fd_ = -1;
    return IoError(reason);
  }
  socklen_t len = sizeof(addr);
  getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  return Status();
}

Status StaticServer::Serve() {
  for (;;) {
    const int fd = accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (stopping_) {
      if (fd >= 0) close(fd);
      return Status();
    }
    if (fd < 0) {
      if (errno == EINTR || errno == ECONNABORTED || errno == EMFILE || errno == ENFILE) {
        if (errno == EMFILE || errno == ENFILE)
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
        continue;
      }
      return IoError(std::string("the server stopped accepting connections: ") +
                     std::strerror(errno));
    }
    timeval timeout{kSocketTimeoutSeconds, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
    setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof(timeout));
    if (shared_->connections.fetch_add(1) >= kMaxConnections) {
      SendSimple(fd, 503, "Service Unavailable", "too many connections\n");
      close(fd);
      shared_->connections.fetch_sub(1);
      continue;
    }
    // The thread keeps the site alive, should it outlive this server.
    std::thread([shared = shared_, fd] {
      HandleConnection(shared->site, fd);
      shutdown(fd, SHUT_WR);
      close(fd);
      shared->connections.fetch_sub(1);
    }).detach();
  }
}

void StaticServer::Stop() {
  stopping_ = true;
  // Wakes a blocked accept(), which then fails and sees stopping_.
  if (listen_fd_ >= 0) shutdown(listen_fd_, SHUT_RDWR);
}

}  // namespace casual3d::cli

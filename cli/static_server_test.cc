#include "cli/static_server.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <thread>
#include <utility>

#include "base/testing/scratch_dir.h"
#include "format/tile_image_format.h"

namespace casual3d::cli {
namespace {
namespace fs = std::filesystem;

using casual3d::testing::WriteWholeFile;

// One request on a fresh connection; the whole response (the server closes).
std::string Exchange(int port, const std::string& request) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  EXPECT_GE(fd, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(static_cast<uint16_t>(port));
  EXPECT_EQ(connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)), 0);
  EXPECT_EQ(send(fd, request.data(), request.size(), 0), static_cast<ssize_t>(request.size()));
  std::string response;
  char buffer[4096];
  for (;;) {
    const ssize_t n = recv(fd, buffer, sizeof(buffer), 0);
    if (n <= 0) break;
    response.append(buffer, static_cast<size_t>(n));
  }
  close(fd);
  return response;
}

std::string Get(int port, const std::string& path, const std::string& method = "GET",
                const std::string& headers = "") {
  return Exchange(port, method + " " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\n" + headers + "\r\n");
}

std::string StatusLine(const std::string& response) {
  return response.substr(0, response.find("\r\n"));
}

std::string Body(const std::string& response) {
  const size_t end = response.find("\r\n\r\n");
  return end == std::string::npos ? "" : response.substr(end + 4);
}

bool HasHeader(const std::string& response, const std::string& line) {
  const std::string head = response.substr(0, response.find("\r\n\r\n") + 2);
  return head.find("\r\n" + line + "\r\n") != std::string::npos;
}

// A server on 127.0.0.1, port 0, serving site/ (with a mounted folder
// mounted/ at /viewer/ and a fallback index page), stopped at the end.
class StaticServerTest : public casual3d::testing::TestWithScratchDir {
 protected:
  void SetUp() override {
    fs::create_directories(dir_ / "site" / "l0");
    fs::create_directories(dir_ / "mounted");
    WriteWholeFile(dir_ / "site" / "manifest.json", "{\"a\": 1}\n");
    WriteWholeFile(dir_ / "site" / "l0" / "0-0.color.webp", "RIFF....WEBP");
    WriteWholeFile(dir_ / "site" / "page.HTML", "<p>hi</p>\n");
    WriteWholeFile(dir_ / "mounted" / "casual3d-viewer.js", "export {};\n");
    WriteWholeFile(dir_ / "secret.txt", "outside the root\n");
  }
  void Start(bool fallback_index = true) {
    StaticSite site;
    site.root = dir_ / "site";
    site.mount = "viewer";
    site.mount_dir = dir_ / "mounted";
    if (fallback_index) site.fallback_index_html = "<title>fallback</title>\n";
    server_ = std::make_unique<StaticServer>(std::move(site));
    ASSERT_TRUE(server_->Listen(0).ok());
    ASSERT_GT(server_->port(), 0);
    thread_ = std::thread([this] { served_ = server_->Serve(); });
  }
  void TearDown() override {
    if (!server_) return;
    server_->Stop();
    thread_.join();
    EXPECT_TRUE(served_.ok()) << served_.message();
  }
  int port() const { return server_->port(); }

  std::unique_ptr<StaticServer> server_;
  std::thread thread_;
  Status served_;
};

TEST(MimeTypeTest, TileFormatsAndUsualWebTypes) {
  EXPECT_EQ(MimeType("l0/0-0.color.webp"), WebpTileImageFormat().mime_type);
  const std::pair<const char*, const char*> kCases[] = {
      {"a/index.html", "text/html; charset=utf-8"},
      {"INDEX.HTML", "text/html; charset=utf-8"},
      {"casual3d-viewer.js", "text/javascript; charset=utf-8"},
      {"m.mjs", "text/javascript; charset=utf-8"},
      {"manifest.json", "application/json"},
      {"casual3d-format.wasm", "application/wasm"},
      {"a.png", "image/png"},
      {"a.jpeg", "image/jpeg"},
      {"a.css", "text/css; charset=utf-8"},
      {"a.svg", "image/svg+xml"},
      {"photo.glb", "model/gltf-binary"},
      {"master.exr", "image/x-exr"},
      {"photo.c3d", "application/octet-stream"},
      {"README", "application/octet-stream"},
  };
  for (const auto& [path, type] : kCases) EXPECT_EQ(MimeType(path), type) << path;
}

TEST_F(StaticServerTest, ServesFilesWithTheirTypes) {
  Start();
  const std::string tile = Get(port(), "/l0/0-0.color.webp");
  EXPECT_EQ(StatusLine(tile), "HTTP/1.1 200 OK");
  EXPECT_TRUE(HasHeader(tile, std::string("Content-Type: ") + WebpTileImageFormat().mime_type));
  EXPECT_TRUE(HasHeader(tile, "Content-Length: 12"));
  EXPECT_TRUE(HasHeader(tile, "Cross-Origin-Opener-Policy: same-origin"));
  EXPECT_TRUE(HasHeader(tile, "Cross-Origin-Embedder-Policy: require-corp"));
  EXPECT_EQ(Body(tile), "RIFF....WEBP");

  const std::string json = Get(port(), "/manifest.json?cache=1");
  EXPECT_EQ(StatusLine(json), "HTTP/1.1 200 OK");
  EXPECT_TRUE(HasHeader(json, "Content-Type: application/json"));
  EXPECT_EQ(Body(json), "{\"a\": 1}\n");

  const std::string page = Get(port(), "/page%2EHTML");
  EXPECT_TRUE(HasHeader(page, "Content-Type: text/html; charset=utf-8"));
  EXPECT_EQ(Body(page), "<p>hi</p>\n");
}

TEST_F(StaticServerTest, HeadSendsTheHeadersOnly) {
  Start();
  const std::string head = Get(port(), "/manifest.json", "HEAD");
  EXPECT_EQ(StatusLine(head), "HTTP/1.1 200 OK");
  EXPECT_TRUE(HasHeader(head, "Content-Length: 9"));
  EXPECT_EQ(Body(head), "");
}

TEST_F(StaticServerTest, OtherMethodsAreRefused) {
  Start();
  EXPECT_EQ(StatusLine(Get(port(), "/manifest.json", "POST")), "HTTP/1.1 405 Method Not Allowed");
  EXPECT_EQ(StatusLine(Exchange(port(), "GET\r\n\r\n")), "HTTP/1.1 400 Bad Request");
}

TEST_F(StaticServerTest, MissingFilesAre404) {
  Start();
  const std::string missing = Get(port(), "/l0/9-9.color.webp");
  EXPECT_EQ(StatusLine(missing), "HTTP/1.1 404 Not Found");
  EXPECT_EQ(Body(missing), "not found\n");
  EXPECT_EQ(StatusLine(Get(port(), "/l0")), "HTTP/1.1 404 Not Found");  // A folder.
}

TEST_F(StaticServerTest, PathsOutsideTheRootAreRefused) {
  Start();
  fs::create_symlink(dir_ / "secret.txt", dir_ / "site" / "link.txt");
  for (const char* path : {"/../secret.txt", "/%2e%2e/secret.txt", "/l0/%2E%2E/../secret.txt",
                           "/./manifest.json", "/l0\\..\\..\\secret.txt", "/a%00b", "relative"}) {
    const std::string response = Get(port(), path);
    EXPECT_EQ(StatusLine(response), "HTTP/1.1 400 Bad Request") << path;
    EXPECT_EQ(response.find("outside the root"), std::string::npos) << path;
  }
  // A symbolic link out of the root is resolved before the check.
  EXPECT_EQ(StatusLine(Get(port(), "/link.txt")), "HTTP/1.1 404 Not Found");
}

TEST_F(StaticServerTest, ByteRanges) {
  Start();
  const std::string part = Get(port(), "/l0/0-0.color.webp", "GET", "Range: bytes=8-11\r\n");
  EXPECT_EQ(StatusLine(part), "HTTP/1.1 206 Partial Content");
  EXPECT_TRUE(HasHeader(part, "Content-Range: bytes 8-11/12"));
  EXPECT_EQ(Body(part), "WEBP");
  const std::string tail = Get(port(), "/l0/0-0.color.webp", "GET", "range: bytes=-4\r\n");
  EXPECT_EQ(Body(tail), "WEBP");
  const std::string beyond = Get(port(), "/l0/0-0.color.webp", "GET", "Range: bytes=12-\r\n");
  EXPECT_EQ(StatusLine(beyond), "HTTP/1.1 416 Range Not Satisfiable");
  EXPECT_TRUE(HasHeader(beyond, "Content-Range: bytes */12"));
  // Several ranges: the whole file, as the RFC allows.
  const std::string several = Get(port(), "/l0/0-0.color.webp", "GET", "Range: bytes=0-1,4-5\r\n");
  EXPECT_EQ(StatusLine(several), "HTTP/1.1 200 OK");
  EXPECT_EQ(Body(several), "RIFF....WEBP");
}

TEST_F(StaticServerTest, MountedFolderFirstThenTheRoot) {
  fs::create_directories(dir_ / "site" / "viewer");
  WriteWholeFile(dir_ / "site" / "viewer" / "casual3d-viewer.js", "old copy\n");
  WriteWholeFile(dir_ / "site" / "viewer" / "only-here.js", "root copy\n");
  Start();
  EXPECT_EQ(Body(Get(port(), "/viewer/casual3d-viewer.js")), "export {};\n");
  EXPECT_EQ(Body(Get(port(), "/viewer/only-here.js")), "root copy\n");
  EXPECT_EQ(StatusLine(Get(port(), "/viewer/../secret.txt")), "HTTP/1.1 400 Bad Request");
}

TEST_F(StaticServerTest, FallbackIndexUnlessTheRootHasOne) {
  Start();
  EXPECT_EQ(Body(Get(port(), "/")), "<title>fallback</title>\n");
  EXPECT_EQ(Body(Get(port(), "/index.html")), "<title>fallback</title>\n");
  WriteWholeFile(dir_ / "site" / "index.html", "<title>own</title>\n");
  EXPECT_EQ(Body(Get(port(), "/")), "<title>own</title>\n");
  EXPECT_EQ(Body(Get(port(), "/index.html")), "<title>own</title>\n");
}

TEST_F(StaticServerTest, NoFallbackIndexIs404) {
  Start(/*fallback_index=*/false);
  EXPECT_EQ(StatusLine(Get(port(), "/")), "HTTP/1.1 404 Not Found");
}

TEST(StaticServerListenTest, BusyPortAndBadPortAreErrors) {
  StaticServer first(StaticSite{});
  ASSERT_TRUE(first.Listen(0).ok());
  StaticServer second(StaticSite{});
  const Status busy = second.Listen(first.port());
  EXPECT_FALSE(busy.ok());
  EXPECT_FALSE(busy.message().empty());
  EXPECT_FALSE(StaticServer(StaticSite{}).Listen(70000).ok());
}

}  // namespace
}  // namespace casual3d::cli

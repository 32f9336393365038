// `casual3d info <package>`: prints what a package (folder or .c3d) holds.

#include <cstdio>
#include <stdexcept>
#include <string>

#include "cli/command.h"
#include "format/file_source.h"
#include "format/manifest.h"
#include "format/tile_image_format.h"

namespace casual3d::cli {
namespace {

void RunInfo(const std::string& path) {
  StatusOr<std::unique_ptr<FileSource>> source = OpenPackage(path);
  if (!source.ok()) throw std::runtime_error(source.status().message());
  StatusOr<std::vector<uint8_t>> bytes = (*source)->Read(kManifestFileName, kMaxManifestBytes);
  if (!bytes.ok()) throw std::runtime_error(path + ": " + bytes.status().message());
  StatusOr<Manifest> m = ParseManifest(
      std::string_view(reinterpret_cast<const char*>(bytes->data()), bytes->size()));
  if (!m.ok()) throw std::runtime_error(path + ": " + m.status().message());
  uint64_t total = bytes->size();
  for (const FileEntry& f : m->files) total += f.bytes;
  std::printf("package      %s\n", path.c_str());
  std::printf("format       casual3d %d.%d%s%s\n", m->version_major, m->version_minor,
              m->generator.empty() ? "" : ", written by ", m->generator.c_str());
  std::printf("panorama     %dx%d equirectangular, two layers (front, back)\n", m->width,
              m->height);
  std::printf("frame        centre (%.6g, %.6g, %.6g) m\n", m->frame.centre[0],
              m->frame.centre[1], m->frame.centre[2]);
  std::printf("depth        log, %d bits, %.6g .. %.6g m (max relative error %.4f%%)\n",
              m->depth.bits, m->depth.near_m, m->depth.far_m,
              100.0 * m->depth.MaxRelativeError());
  if (m->normal.lossy())
    std::printf("normals      octahedral, lossy: per tile mean error at most %g, 99th percentile "
                "at most %g degrees\n",
                m->normal.mean_error_deg, m->normal.p99_error_deg);
  else
    std::printf("normals      octahedral, %d bits per coordinate\n", m->normal.bits);
  if (m->view) {
    const ViewHints& v = *m->view;
    const char* unit = v.metric ? " m" : " (the capture's units)";
    std::printf("view         opens at yaw %.1f, pitch %.1f, field of view %.1f deg\n", v.yaw_deg,
                v.pitch_deg, v.fov_deg);
    std::printf("content      yaw %.1f .. %.1f, pitch %.1f .. %.1f deg\n", v.content_yaw_min_deg,
                v.content_yaw_max_deg, v.content_pitch_min_deg, v.content_pitch_max_deg);
    std::printf("volume       radius %.6g%s\n", v.volume_radius, unit);
  } else {
    std::printf("view         none: viewers choose\n");
  }
  StatusOr<const TileImageFormat*> images = TileImageFormatOf(*m);
  if (!images.ok()) throw std::runtime_error(path + ": " + images.status().message());
  std::printf("tiles        %d px, %s images (%s)\n", m->tile_size, (*images)->label,
              (*images)->mime_type);
  for (size_t l = 0; l < m->levels.size(); ++l) {
    const LevelEntry& L = m->levels[l];
    std::printf("level %zu      %dx%d, %dx%d tiles, %.1f KB\n", l, L.width, L.height, L.columns,
                L.rows, m->LevelBytes(static_cast<int>(l)) / 1024.0);
  }
  std::printf("files        %zu + manifest.json (%zu bytes), %.1f KB in all\n", m->files.size(),
              bytes->size(), total / 1024.0);
}

}  // namespace

void AddInfoCommand(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("info", "Describe a package (folder or .c3d file)");
  cmd->add_option("package", *path, "Package folder or .c3d file")->required();
  cmd->callback([path] { RunInfo(*path); });
}

}  // namespace casual3d::cli

// `casual3d export <input> --glb out.glb [--draco] [--max-triangles N] ...`:
// writes a 3D photo as a binary glTF file (encoder/gltf_export.h): the mesh of
// the two-layer panorama, simplified to a triangle budget (format/
// mesh_simplify.h), with its colour atlas as texture.
//
// The input is a package folder (holding manifest.json), a single-file package
// (.c3d) or a master file (OpenEXR), recognised by content, not by name.

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/parallel_for.h"
#include "cli/command.h"
#include "cli/described_option.h"
#include "cli/export_options.h"
#include "encoder/gltf_export.h"
#include "encoder/master_file.h"
#include "encoder/tile_image_codec.h"
#include "format/file_source.h"
#include "format/mesh_builder.h"
#include "format/mesh_simplify.h"
#include "format/package_reader.h"
#include "format/single_file.h"
#include "reconstruct/util/log.h"

namespace casual3d::cli {
namespace fs = std::filesystem;
namespace {

// The largest single-file package read into memory.
constexpr uint64_t kMaxSingleFileBytes = uint64_t{4} << 30;

[[noreturn]] void Fail(const std::string& message) { throw std::runtime_error(message); }

std::string Megabytes(size_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.2f MB", bytes / 1e6);
  return buf;
}

std::string Number(double value) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", value);
  return buf;
}

// Reads the panorama from whatever `input` is. *depth_code_step receives the
// relative depth step between neighbouring codes of a package (spec Sec. 4.2),
// 0 for a master file, whose depth is exact.
TwoLayerPanorama LoadPanorama(const ExportOptions& opts, double* depth_code_step) {
  *depth_code_step = 0.0;
  const std::string& input = opts.input;
  std::error_code ec;
  const fs::file_status st = fs::status(input, ec);
  if (ec || !fs::exists(st)) Fail(input + ": no such file or folder");

  ReadOptions read;
  read.level = opts.level;
  read.num_threads = base::ResolveThreads(opts.num_threads);
  if (read.num_threads > 256) read.num_threads = 256;

  auto read_package = [&](const FileSource& source) {
    Manifest manifest;
    auto pano = ReadPackage(source, encoder::TileImageDecoders(), read, &manifest);
    if (!pano.ok()) Fail(input + ": " + pano.status().ToString());
    const double half_step = manifest.depth.MaxRelativeError();
    *depth_code_step = (1.0 + half_step) * (1.0 + half_step) - 1.0;
    return std::move(pano).value();
  };

  if (fs::is_directory(st)) {
    if (!fs::exists(fs::path(input) / "manifest.json")) {
      Fail(input +
           ": not a package folder (no manifest.json); pass a package folder, a .c3d "
           "file or a master .exr file");
    }
    return read_package(FolderFileSource(input));
  }

  // A file: look at its first bytes.
  std::ifstream in(input, std::ios::binary);
  if (!in) Fail(input + ": cannot open (" + std::strerror(errno) + ")");
  unsigned char magic[8] = {};
  in.read(reinterpret_cast<char*>(magic), sizeof(magic));
  const std::streamsize got = in.gcount();
  static const unsigned char kExrMagic[4] = {0x76, 0x2f, 0x31, 0x01};
  if (got >= 4 && std::memcmp(magic, kExrMagic, 4) == 0) {
    if (opts.level != 0) Fail(input + ": a master file has one level only; drop --level");
    auto pano = encoder::ReadMasterFile(input);
    if (!pano.ok()) Fail(input + ": " + pano.status().ToString());
    return std::move(pano).value();
  }
  if (got == 8 && std::memcmp(magic, kSingleFileMagic, 8) == 0) {
    const uint64_t size = fs::file_size(input, ec);
    if (ec) Fail(input + ": cannot read its size (" + ec.message() + ")");
    if (size > kMaxSingleFileBytes) {
      Fail(input + ": " + std::to_string(size) +
           " bytes, more than the 4 GiB a single-file "
           "package may have here; unpack it into a folder");
    }
    std::vector<uint8_t> bytes(static_cast<size_t>(size));
    in.seekg(0);
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
    if (in.gcount() != static_cast<std::streamsize>(size)) Fail(input + ": read failed");
    auto source = SingleFileSource::Create(std::move(bytes));
    if (!source.ok()) Fail(input + ": " + source.status().ToString());
    return read_package(**source);
  }
  Fail(input +
       ": neither a package folder, a single-file package (.c3d) nor a master file "
       "(.exr)");
}

void RunExport(ExportOptions& opts) {
  const auto start = std::chrono::steady_clock::now();
  opts.gltf.texture_format =
      opts.texture == "png" ? encoder::TextureFormat::kPng : encoder::TextureFormat::kJpeg;
  opts.gltf.unlit = !opts.lit;
  opts.gltf.normals = !opts.no_normals;
  // Options first, so that a bad value fails before any work.
  if (Status s = opts.Check(); !s.ok()) Fail(s.message());
  const fs::path out_dir = fs::absolute(opts.glb).parent_path();
  if (!fs::is_directory(out_dir)) {
    Fail(opts.glb + ": the folder " + out_dir.string() + " does not exist; create it first");
  }

  auto since = [](std::chrono::steady_clock::time_point t) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), " (%.2f s)",
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count());
    return std::string(buf);
  };
  // Three stages: read, build the mesh, encode and write.
  util::Progress progress("export", 3);
  double depth_code_step = 0.0;
  const TwoLayerPanorama pano = LoadPanorama(opts, &depth_code_step);
  progress.Advance();
  util::LogInfo("read " + opts.input + ": " + std::to_string(pano.width()) + "x" +
                std::to_string(pano.height()) + " panorama" + since(start));
  const auto mesh_start = std::chrono::steady_clock::now();

  Mesh mesh;
  if (!opts.no_simplify) {
    opts.simplify_options.max_pixels = std::max<int64_t>(
        opts.simplify_options.max_pixels, static_cast<int64_t>(pano.width()) * pano.height());
    opts.simplify_options.validate_input = false;  // The readers validated it.
    // A package's depth is a staircase of code steps: --max-error is counted
    // beyond one step, as the viewer does (spec Sec. 4.2).
    opts.simplify_options.max_relative_error =
        std::min(0.5, opts.simplify_options.max_relative_error + depth_code_step);
    auto simplified = BuildSimplifiedMesh(pano, opts.simplify_options);
    if (!simplified.ok()) Fail(opts.input + ": " + simplified.status().ToString());
    if (!simplified->budget_met) {
      util::LogWarning("the mesh keeps " + std::to_string(simplified->mesh.num_triangles()) +
                       " triangles, over --max-triangles " +
                       std::to_string(opts.simplify_options.max_triangles) +
                       ", because --max-error " + Number(opts.simplify_options.max_relative_error) +
                       " allows no coarser mesh");
    }
    util::LogInfo("simplified " + std::to_string(simplified->full_triangles) + " to " +
                  std::to_string(simplified->mesh.num_triangles()) +
                  " triangles, relative depth error at most " + Number(simplified->error_bound) +
                  since(mesh_start));
    mesh = std::move(simplified->mesh);
  } else {
    MeshBuildOptions build;
    build.max_pixels =
        std::max<int64_t>(build.max_pixels, static_cast<int64_t>(pano.width()) * pano.height());
    build.validate_input = false;
    auto full = BuildMesh(pano, build);
    if (!full.ok()) Fail(opts.input + ": " + full.status().ToString());
    mesh = std::move(full).value();
  }
  if (mesh.num_triangles() == 0) Fail(opts.input + ": the 3D photo has no triangles to export");
  progress.Advance();

  encoder::GltfExportStats stats;
  const auto write_start = std::chrono::steady_clock::now();
  const Status written =
      encoder::ExportGlb(mesh, encoder::BuildColorAtlas(pano), opts.gltf, opts.glb, &stats);
  if (!written.ok()) Fail(written.message());
  util::LogInfo("encoded and wrote the GLB" + since(write_start));
  progress.Finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  char draco[64] = "";
  if (opts.gltf.draco)
    std::snprintf(draco, sizeof(draco), " (Draco, %d-bit positions)", stats.draco_position_bits);
  char line[512];
  std::snprintf(line, sizeof(line),
                "wrote %s: %zu vertices, %zu triangles, %dx%d %s texture (%s), mesh %s%s, "
                "%s in total, %.2f s",
                opts.glb.c_str(), stats.num_vertices, stats.num_triangles, stats.texture_width,
                stats.texture_height, opts.texture == "png" ? "PNG" : "JPEG",
                Megabytes(stats.texture_bytes).c_str(), Megabytes(stats.mesh_bytes).c_str(),
                draco, Megabytes(stats.file_bytes).c_str(), seconds);
  // The result goes to stdout (logs and progress go to stderr).
  std::printf("%s\n", line);
}

}  // namespace

void AddExportCommand(CLI::App& app) {
  auto opts = std::make_shared<ExportOptions>();
  CLI::App* cmd = app.add_subcommand(
      "export", "Write a 3D photo as a binary glTF (GLB) file: mesh, normals and colour texture");
  cmd->add_option("input", opts->input,
                  "Package folder, single-file package (.c3d) or master file (.exr)")
      ->required();
  cmd->add_option("--glb", opts->glb, "Output GLB file (written atomically)")->required();
  cmd->add_flag("--draco", opts->gltf.draco,
                "Compress the mesh with Draco (KHR_draco_mesh_compression)");
  AddDescribedOption(cmd, "--max-triangles", *opts, opts->simplify_options.max_triangles);
  AddDescribedOption(cmd, "--max-error", *opts, opts->simplify_options.max_relative_error);
  cmd->add_flag("--no-simplify", opts->no_simplify, "Export the full mesh, one vertex per node");
  AddDescribedOption(cmd, "--level", *opts, opts->level);
  AddDescribedOption(cmd, "--texture", *opts, opts->texture);
  AddDescribedOption(cmd, "--jpeg-quality", *opts, opts->gltf.jpeg_quality);
  AddDescribedOption(cmd, "--max-texture-size", *opts, opts->gltf.max_texture_size);
  cmd->add_flag("--no-normals", opts->no_normals, "Leave out the NORMAL attribute");
  cmd->add_flag("--lit", opts->lit,
                "Lit PBR material instead of KHR_materials_unlit (the photo's colours already "
                "hold the scene's lighting)");
  cmd->add_flag("--double-sided", opts->gltf.double_sided, "Render both sides of triangles");
  AddDescribedOption(cmd, "--draco-position-bits", *opts, opts->gltf.draco_position_bits);
  AddDescribedOption(cmd, "--draco-normal-bits", *opts, opts->gltf.draco_normal_bits);
  AddDescribedOption(cmd, "--draco-texcoord-bits", *opts, opts->gltf.draco_texcoord_bits);
  AddDescribedOption(cmd, "--draco-level", *opts, opts->gltf.draco_compression_level);
  AddDescribedOption(cmd, "--threads", *opts, opts->num_threads);
  cmd->callback([opts]() { RunExport(*opts); });
}

}  // namespace casual3d::cli

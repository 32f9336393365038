#include "reconstruct/pipeline/pipeline.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "base/atomic_file.h"
#include "encoder/master_file.h"
#include "encoder/package_writer.h"
#include "format/sha256.h"
#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/io/file_util.h"
#include "reconstruct/pipeline/capture_shape.h"
#include "reconstruct/pipeline/holdout.h"
#include "reconstruct/util/log.h"
#include "reconstruct/util/options_json.h"

namespace casual3d::pipeline {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Bump when a stage's output format or algorithm changes, so old caches are stale.
// sparse-3: the import skips bad and duplicate files, reads HEIF, TIFF and video.
// sparse-4, dense-5, panorama-7: the key lists every field of the stage's
// options from their description (util::FieldsKeyText; pipeline.h, "Cache
// key"); panorama-7 also takes over the version (panorama-6) the panorama key
// text used to carry. panorama-8: stitched colour and depth blended across
// the photos that agree, depth smoothed along surfaces
// (spec/stage-panorama.md, version 7). encode-3: coarser levels take the mean
// normal of their block, the manifest is compact.
constexpr const char* kStageVersions[kNumStages] = {"sparse-4", "dense-5", "panorama-8",
                                                    "encode-3"};

std::string HashHex(const std::string& text) {
  return Sha256Hex(reinterpret_cast<const uint8_t*>(text.data()), text.size());
}

// Names, sizes and modification times of every file below `input`: a change
// to any photo makes the sparse stage (and all after it) stale.
std::string InputFingerprint(const std::string& input) {
  std::vector<std::string> rows;
  std::error_code ec;
  if (fs::is_regular_file(input, ec)) {  // A video clip.
    return std::to_string(fs::file_size(input, ec)) + " " +
           std::to_string(fs::last_write_time(input, ec).time_since_epoch().count()) + "\n";
  }
  for (auto it = fs::recursive_directory_iterator(input, ec); !ec && it != fs::end(it);
       it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    const auto size = it->file_size(ec);
    const auto mtime = it->last_write_time(ec).time_since_epoch().count();
    rows.push_back(fs::relative(it->path(), input, ec).string() + " " + std::to_string(size) + " " +
                   std::to_string(mtime));
  }
  if (ec) throw std::runtime_error(input + ": cannot list the input folder (" + ec.message() + ")");
  std::sort(rows.begin(), rows.end());
  std::string out;
  for (const std::string& r : rows) out += r + "\n";
  return out;
}

std::string ReadKey(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return "";
  try {
    return io::ReadFile(path.string());
  } catch (const std::exception&) {
    return "";
  }
}

// Runs `run(tmp_dir)` into a fresh temporary folder next to `dir`, then
// replaces `dir` by it and records `key`, so that `dir` is either absent,
// or complete and labelled with the key it was made from.
template <typename Fn>
void RunIntoFolder(const fs::path& dir, const fs::path& key_path, const std::string& key, Fn run) {
  const fs::path tmp = dir.string() + ".tmp";
  std::error_code ec;
  fs::remove_all(tmp, ec);
  fs::remove(key_path, ec);
  run(tmp);
  io::ThrowIfError(base::ReplaceFolder(tmp.string(), dir.string()));
  io::WriteFileAtomic(key_path.string(), key);
}

}  // namespace

const char* StageName(Stage stage) {
  switch (stage) {
    case Stage::kSparse:
      return "sparse";
    case Stage::kDense:
      return "dense";
    case Stage::kPanorama:
      return "panorama";
    case Stage::kEncode:
      return "encode";
  }
  return "?";
}

bool StageFromName(const std::string& name, Stage* stage) {
  for (int s = 0; s < kNumStages; ++s) {
    if (name == StageName(static_cast<Stage>(s))) {
      *stage = static_cast<Stage>(s);
      return true;
    }
  }
  return false;
}

Status PipelineOptions::Check() const {
  if (static_cast<int>(from) > static_cast<int>(to)) {
    return InvalidArgument(std::string("--from ") + StageName(from) + " comes after --to " + StageName(to));
  }
  if (!(color_quality >= 0 && color_quality <= 100)) return InvalidArgument("color_quality: must be in [0, 100]");
  if (num_threads < 0) return InvalidArgument("num_threads: must be >= 0");
  if (holdout_every < 0 || holdout_every > 1000) return InvalidArgument("holdout_every: must be in [0, 1000]");
  for (const Status& s : {sparse.Check(), dense.Check(), panorama.Check()})
    if (!s.ok()) return s;
  return Status::Ok();
}

PipelineReport RunPipeline(const std::string& input, const std::string& out,
                           const PipelineOptions& options_in) {
  if (const Status st = options_in.Check(); !st.ok()) throw std::invalid_argument(st.message());
  PipelineOptions options = options_in;
  options.sparse.num_threads = options.num_threads;
  options.dense.num_threads = options.num_threads;
  options.panorama.num_threads = options.num_threads;
  const auto start = Clock::now();

  std::error_code ec;
  if (!fs::is_directory(input, ec) && !sfm::IsVideoFileName(input)) {
    throw std::runtime_error(input + ": not a folder of photos, a video or a COLMAP workspace");
  }
  const fs::path root(out);
  const fs::path work = root / "work";
  fs::create_directories(work, ec);
  if (ec)
    throw std::runtime_error(out + ": cannot create the output folder (" + ec.message() + ")");

  const fs::path dirs[kNumStages] = {work / "sparse", work / "dense", work / "panorama",
                                     root / "web"};
  fs::path key_paths[kNumStages];
  std::string keys[kNumStages];
  for (int s = 0; s < kNumStages; ++s) {
    key_paths[s] = work / (std::string(StageName(static_cast<Stage>(s))) + ".key");
  }
  // The canonical path, so that "a/../b" and "b" share the cache.
  keys[0] = HashHex(std::string(kStageVersions[0]) + "\n" +
                    fs::weakly_canonical(fs::absolute(input)).string() + "\n" +
                    InputFingerprint(input) + util::FieldsKeyText(options.sparse));
  keys[1] = HashHex(
      std::string(kStageVersions[1]) + "\n" + keys[0] + "\n" + util::FieldsKeyText(options.dense) +
      (options.holdout_every > 0 ? "\nholdout " + std::to_string(options.holdout_every) : ""));
  // The dense and panorama stages read the training workspace (holdout.h)
  // when photos are held out, written once the sparse output exists.
  std::vector<std::string> holdout;
  fs::path train_dir;
  const auto input_workspace = [&]() -> fs::path {
    if (options.holdout_every <= 0) return dirs[0];
    if (train_dir.empty()) {
      std::vector<std::string> names;
      for (const auto& [id, image] : geometry::ReadModel((dirs[0] / "sparse").string()).images)
        names.push_back(image.name);
      holdout = HoldoutNames(names, options.holdout_every);
      train_dir = work / "train";
      WriteTrainingWorkspace(dirs[0].string(), holdout, train_dir.string());
    }
    return train_dir;
  };
  keys[2] = HashHex(std::string(kStageVersions[2]) + "\n" + keys[1] + "\n" +
                    util::FieldsKeyText(options.panorama));
  keys[3] =
      HashHex(std::string(kStageVersions[3]) + "\n" + keys[2] + "\n" +
              std::to_string(options.color_quality) + " " + std::to_string(options.tile_size));

  // The previous report.json, if any: cached stages keep the timings and
  // results recorded when they ran (matched by their key).
  nlohmann::json previous;
  if (fs::exists(root / "report.json", ec)) {
    try {
      previous = nlohmann::json::parse(io::ReadFile((root / "report.json").string()));
    } catch (const std::exception&) {
      previous = nullptr;  // Unreadable: start afresh.
    }
  }
  const auto previous_stage = [&](int s) -> nlohmann::json {
    if (!previous.is_object() || !previous.contains("stages") || !previous["stages"].is_array())
      return nullptr;
    for (const auto& e : previous["stages"]) {
      if (e.is_object() && e.value("stage", "") == StageName(static_cast<Stage>(s)) &&
          e.value("key", "") == keys[s])
        return e;
    }
    return nullptr;
  };

  PipelineReport report;
  nlohmann::json stage_json = nlohmann::json::object();
  std::optional<TwoLayerPanorama> fresh_panorama;  // Made by this run's panorama stage.
  // The capture's shape and advice (capture_shape.h), once the sparse
  // output is current; advice, not a requirement: a failure only warns.
  nlohmann::json capture_json;
  const auto measure_capture = [&] {
    if (!fs::exists(dirs[0], ec) || ReadKey(key_paths[0]) != keys[0]) return;
    try {
      const CaptureShape shape = MeasureWorkspaceCaptureShape(dirs[0].string());
      capture_json = CaptureShapeJson(shape);
      report.capture_advice = shape.advice;
      for (size_t k = 0; k < shape.advice.size(); ++k)
        (k == 0 ? util::LogInfo : util::LogWarning)("capture: " + shape.advice[k]);
    } catch (const std::exception& e) {
      util::LogWarning(std::string("capture: not measured (") + e.what() + ")");
    }
  };
  for (int s = 0; s < kNumStages; ++s) {
    const Stage stage = static_cast<Stage>(s);
    if (stage == Stage::kDense) measure_capture();
    StageRun run;
    run.stage = StageName(stage);
    const bool current = fs::exists(dirs[s], ec) && ReadKey(key_paths[s]) == keys[s];
    const bool selected = s >= static_cast<int>(options.from) && s <= static_cast<int>(options.to);
    if (!selected) {
      if (s < static_cast<int>(options.from) && !current) {
        throw std::runtime_error(std::string("stage ") + run.stage + " has no current output in " +
                                 work.string() + ": run it first (or drop --from)");
      }
      if (s > static_cast<int>(options.to)) break;
      run.cached = true;
      report.stages.push_back(run);
      continue;
    }
    if (current && !options.force) {
      util::LogInfo(std::string("stage ") + run.stage + ": up to date, skipped");
      run.cached = true;
      report.stages.push_back(run);
      continue;
    }
    const auto t = Clock::now();
    switch (stage) {
      case Stage::kSparse: {
        // The sparse stage writes OUT.tmp-XXXX and renames it itself.
        sfm::SparseStageOptions sparse = options.sparse;
        sparse.overwrite = true;
        fs::remove(key_paths[s], ec);
        const sfm::SparseStageResult r = sfm::RunSparseStage(input, dirs[s].string(), sparse);
        io::WriteFileAtomic(key_paths[s].string(), keys[s]);
        nlohmann::json skipped = nlohmann::json::array();
        for (const sfm::SkippedPhoto& p : r.skipped)
          skipped.push_back({{"file", p.file}, {"reason", p.reason}});
        stage_json["sparse"] = {{"input_type", r.input_type},
                                {"photos", r.num_photos},
                                {"registered", r.num_registered},
                                {"unregistered", r.unregistered},
                                {"skipped", skipped},
                                {"points", r.num_points},
                                {"mean_reprojection_error_px", r.mean_reprojection_error_px}};
        if (r.input_type == "video") {
          stage_json["sparse"]["video"] = {{"frames", r.video.frames_decoded},
                                           {"picked", r.video.picked.size()},
                                           {"blurred", r.video.blurred},
                                           {"rotation_deg", r.video.rotation_deg},
                                           {"frame_selection_seconds", r.video.seconds}};
        }
        break;
      }
      case Stage::kDense: {
        RunIntoFolder(dirs[s], key_paths[s], keys[s], [&](const fs::path& tmp) {
          const depth::DenseReport r =
              depth::RunDenseStage(input_workspace().string(), tmp.string(), options.dense);
          stage_json["dense"] = {{"photos", r.photos.size()}, {"seconds", r.seconds_total}};
        });
        break;
      }
      case Stage::kPanorama: {
        RunIntoFolder(dirs[s], key_paths[s], keys[s], [&](const fs::path& tmp) {
          PanoramaStageReport r;
          fresh_panorama = RunPanoramaStage(input_workspace().string(), dirs[1].string(),
                                            tmp.string(), options.panorama, &r);
          stage_json["panorama"] = {
              {"width", r.width},
              {"front_coverage", r.front_coverage},
              {"fov_covered_fraction", r.front_fov.covered_fraction},
              {"fov_holes", r.front_fov.num_holes},
              {"fov_largest_hole_fraction", r.front_fov.largest_hole_fraction},
              {"footprint_covered_fraction", r.front_footprint.covered_fraction},
              {"footprint_largest_hole_fraction", r.front_footprint.largest_hole_fraction},
              {"back_nodes", r.fuse.back_nodes_in - r.fuse.back_nodes_redundant +
                                 r.fuse.back_nodes_hallucinated}};
        });
        break;
      }
      case Stage::kEncode: {
        const fs::path master = dirs[2] / "master.exr";
        // The panorama this run made is the master file's content (its round
        // trip is exact); only a cached one is read back.
        StatusOr<TwoLayerPanorama> pano = fresh_panorama
                                              ? StatusOr<TwoLayerPanorama>(std::move(*fresh_panorama))
                                              : encoder::ReadMasterFile(master.string());
        fresh_panorama.reset();
        if (!pano.ok()) throw std::runtime_error(pano.status().ToString());
        encoder::PackageOptions package = encoder::DeliveryPackageOptions();
        package.color_quality = options.color_quality;
        package.tile_size = options.tile_size;
        package.num_threads = options.num_threads;
        encoder::PackageStats stats;
        auto files = encoder::EncodePackage(*pano, package, &stats);
        if (!files.ok()) throw std::runtime_error(files.status().ToString());
        fs::remove(key_paths[s], ec);
        Status st = encoder::WritePackageFolder(*files, dirs[s].string());
        if (!st.ok()) throw std::runtime_error(st.ToString());
        if (options.finish_web_package)
          options.finish_web_package(dirs[s].string(), report.capture_advice);
        st = encoder::WritePackageSingleFile(*files, (root / "photo.c3d").string());
        if (!st.ok()) throw std::runtime_error(st.ToString());
        // The archival master and the previews next to the package.
        io::WriteFileAtomic((root / "master.exr").string(), io::ReadFile(master.string()));
        const fs::path preview = dirs[2] / "preview";
        if (fs::exists(preview, ec)) {
          fs::create_directories(root / "preview", ec);
          for (const auto& entry : fs::directory_iterator(preview, ec)) {
            io::WriteFileAtomic((root / "preview" / entry.path().filename()).string(),
                                io::ReadFile(entry.path().string()));
          }
        }
        report.package_bytes = stats.total_bytes;
        io::WriteFileAtomic(key_paths[s].string(), keys[s]);
        stage_json["encode"] = {{"package_bytes", stats.total_bytes}, {"files", stats.num_files}};
        break;
      }
    }
    run.ran = true;
    run.seconds = std::chrono::duration<double>(Clock::now() - t).count();
    report.stages.push_back(run);
  }
  if (fs::exists(dirs[3] / "manifest.json", ec)) report.web_dir = dirs[3].string();
  report.seconds_total = std::chrono::duration<double>(Clock::now() - start).count();

  nlohmann::json j;
  j["input"] = fs::absolute(input).string();
  j["seconds_total"] = report.seconds_total;
  for (size_t s = 0; s < report.stages.size(); ++s) {
    const StageRun& r = report.stages[s];
    nlohmann::json e = {{"stage", r.stage},
                        {"cached", r.cached},
                        {"ran", r.ran},
                        {"seconds", r.seconds},
                        {"key", keys[s]}};
    // A cached stage reports the time it took when it ran, and its results.
    if (r.cached) {
      const nlohmann::json old = previous_stage(static_cast<int>(s));
      if (old.is_object() && old.contains("seconds") && old["seconds"].is_number()) {
        e["seconds"] = old["seconds"];
        if (previous.contains("results") && previous["results"].contains(r.stage) &&
            !stage_json.contains(r.stage))
          stage_json[r.stage] = previous["results"][r.stage];
      }
    }
    j["stages"].push_back(e);
  }
  // Stages after --to keep their entries while their inputs are unchanged.
  for (int s = static_cast<int>(report.stages.size()); s < kNumStages; ++s) {
    const nlohmann::json old = previous_stage(s);
    if (!old.is_object()) continue;
    j["stages"].push_back(old);
    const std::string name = StageName(static_cast<Stage>(s));
    if (previous.contains("results") && previous["results"].contains(name))
      stage_json[name] = previous["results"][name];
  }
  j["results"] = stage_json;
  // Every option of the stages, as their descriptions give them.
  j["options"] = {{"sparse", util::FieldsJson(options.sparse)},
                  {"dense", util::FieldsJson(options.dense)},
                  {"panorama", util::FieldsJson(options.panorama)}};
  if (!capture_json.is_null()) j["capture"] = capture_json;
  // Files of the input the import left out (bad or duplicate), at the top level.
  if (stage_json.contains("sparse") && stage_json["sparse"].contains("skipped"))
    j["skipped"] = stage_json["sparse"]["skipped"];
  if (options.holdout_every > 0 && fs::exists(dirs[0] / "sparse", ec)) {
    input_workspace();
    j["holdout_every"] = options.holdout_every;
    j["holdout"] = holdout;
  }
  io::WriteFileAtomic((root / "report.json").string(), j.dump(2) + "\n");
  return report;
}

}  // namespace casual3d::pipeline

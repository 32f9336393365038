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
#include "encoder/package_fit.h"
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
// normal of their block, the manifest is compact. encode-4: 9-bit depth.
// encode-5: package 2.0 (no 2048-wide level, links stored once).
// sparse-5: COLMAP's steps on one thread (the same photos, the same model).
// panorama-9: the nearest front surface two warps agree on (spec version 8);
// panorama-10: only fragments stretched at most 0.2 support it (version 9).
// panorama-11: the back layer grows only as far as a moving eye can open the
// gap behind each front node (version 10).
// sparse-6: a photo's near depth also bounded by other photos' points inside
// its view (spec/stage-sparse.md, depth_ranges.json).
// panorama-12: the seams between sets of blended photos evened out (version 11).
constexpr const char* kStageVersions[kNumStages] = {"sparse-6", "dense-5", "panorama-12",
                                                    "encode-5"};

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
  if (max_package_kb < 0) return InvalidArgument("max_package_kb: must be >= 0 (0 = no budget)");
  if (holdout_every < 0 || holdout_every > 1000) return InvalidArgument("holdout_every: must be in [0, 1000]");
  for (const Status& s : {sparse.Check(), dense.Check(), panorama.Check()})
    if (!s.ok()) return s;
  return Status::Ok();
}

namespace {

// One run of the pipeline: its folders, the stages' cache keys, the previous
// report.json and what this run's stages report.
class PipelineRun {
 public:
  PipelineRun(const std::string& input, const std::string& out, const PipelineOptions& options)
      : input_(input), options_(options), root_(out), work_(root_ / "work"),
        dirs_{work_ / "sparse", work_ / "dense", work_ / "panorama", root_ / "web"} {
    for (int s = 0; s < kNumStages; ++s) {
      key_paths_[s] = work_ / (std::string(StageName(static_cast<Stage>(s))) + ".key");
    }
    MakeKeys();
    ReadPreviousReport();
  }

  // Runs the selected stages in order (the capture measured before the
  // dense stage), then writes report.json.
  PipelineReport Run(Clock::time_point start) {
    std::error_code ec;
    for (int s = 0; s < kNumStages; ++s) {
      const Stage stage = static_cast<Stage>(s);
      if (stage == Stage::kDense) MeasureCapture();
      StageRun run;
      run.stage = StageName(stage);
      const bool current = fs::exists(dirs_[s], ec) && ReadKey(key_paths_[s]) == keys_[s];
      const bool selected = s >= static_cast<int>(options_.from) && s <= static_cast<int>(options_.to);
      if (!selected) {
        if (s < static_cast<int>(options_.from) && !current) {
          throw std::runtime_error(std::string("stage ") + run.stage + " has no current output in " +
                                   work_.string() + ": run it first (or drop --from)");
        }
        if (s > static_cast<int>(options_.to)) break;
        run.cached = true;
        report_.stages.push_back(run);
        continue;
      }
      if (current && !options_.force) {
        util::LogInfo(std::string("stage ") + run.stage + ": up to date, skipped");
        run.cached = true;
        report_.stages.push_back(run);
        continue;
      }
      const auto t = Clock::now();
      RunStage(stage);
      run.ran = true;
      run.seconds = std::chrono::duration<double>(Clock::now() - t).count();
      report_.stages.push_back(run);
    }
    if (fs::exists(dirs_[3] / "manifest.json", ec)) report_.web_dir = dirs_[3].string();
    report_.seconds_total = std::chrono::duration<double>(Clock::now() - start).count();
    io::WriteFileAtomic((root_ / "report.json").string(), ReportJson().dump(2) + "\n");
    return report_;
  }

 private:
  // The stages' cache keys, each over the one before (pipeline.h, "Cache key").
  void MakeKeys() {
    // The canonical path, so that "a/../b" and "b" share the cache.
    keys_[0] = HashHex(std::string(kStageVersions[0]) + "\n" +
                       fs::weakly_canonical(fs::absolute(input_)).string() + "\n" +
                       InputFingerprint(input_) + util::FieldsKeyText(options_.sparse));
    keys_[1] = HashHex(
        std::string(kStageVersions[1]) + "\n" + keys_[0] + "\n" + util::FieldsKeyText(options_.dense) +
        (options_.holdout_every > 0 ? "\nholdout " + std::to_string(options_.holdout_every) : ""));
    keys_[2] = HashHex(std::string(kStageVersions[2]) + "\n" + keys_[1] + "\n" +
                       util::FieldsKeyText(options_.panorama));
    keys_[3] =
        HashHex(std::string(kStageVersions[3]) + "\n" + keys_[2] + "\n" +
                std::to_string(options_.color_quality) + " " + std::to_string(options_.tile_size) +
                (options_.max_package_kb > 0 ? " max " + std::to_string(options_.max_package_kb) : ""));
  }

  // The previous report.json, if any: cached stages keep the timings and
  // results recorded when they ran (matched by their key).
  void ReadPreviousReport() {
    std::error_code ec;
    if (!fs::exists(root_ / "report.json", ec)) return;
    try {
      previous_ = nlohmann::json::parse(io::ReadFile((root_ / "report.json").string()));
    } catch (const std::exception&) {
      previous_ = nullptr;  // Unreadable: start afresh.
    }
  }

  // Stage s's entry in the previous report if it was made with today's key;
  // null otherwise.
  nlohmann::json PreviousStage(int s) const {
    if (!previous_.is_object() || !previous_.contains("stages") || !previous_["stages"].is_array())
      return nullptr;
    for (const auto& e : previous_["stages"]) {
      if (e.is_object() && e.value("stage", "") == StageName(static_cast<Stage>(s)) &&
          e.value("key", "") == keys_[s])
        return e;
    }
    return nullptr;
  }

  // The workspace the dense and panorama stages read: the training
  // workspace (holdout.h) when photos are held out, written once the sparse
  // output exists.
  fs::path InputWorkspace() {
    if (options_.holdout_every <= 0) return dirs_[0];
    if (train_dir_.empty()) {
      std::vector<std::string> names;
      for (const auto& [id, image] : geometry::ReadModel((dirs_[0] / "sparse").string()).images)
        names.push_back(image.name);
      holdout_ = HoldoutNames(names, options_.holdout_every);
      train_dir_ = work_ / "train";
      WriteTrainingWorkspace(dirs_[0].string(), holdout_, train_dir_.string());
    }
    return train_dir_;
  }

  // The capture's shape and advice (capture_shape.h), once the sparse
  // output is current; advice, not a requirement: a failure only warns.
  void MeasureCapture() {
    std::error_code ec;
    if (!fs::exists(dirs_[0], ec) || ReadKey(key_paths_[0]) != keys_[0]) return;
    try {
      const CaptureShape shape = MeasureWorkspaceCaptureShape(dirs_[0].string());
      capture_json_ = CaptureShapeJson(shape);
      report_.capture_advice = shape.advice;
      for (size_t k = 0; k < shape.advice.size(); ++k)
        (k == 0 ? util::LogInfo : util::LogWarning)("capture: " + shape.advice[k]);
    } catch (const std::exception& e) {
      util::LogWarning(std::string("capture: not measured (") + e.what() + ")");
    }
  }

  void RunStage(Stage stage) {
    const int s = static_cast<int>(stage);
    switch (stage) {
      case Stage::kSparse:
        RunSparse();
        break;
      case Stage::kDense:
        RunIntoFolder(dirs_[s], key_paths_[s], keys_[s], [&](const fs::path& tmp) {
          const depth::DenseReport r =
              depth::RunDenseStage(InputWorkspace().string(), tmp.string(), options_.dense);
          stage_json_["dense"] = {{"photos", r.photos.size()}, {"seconds", r.seconds_total}};
        });
        break;
      case Stage::kPanorama:
        RunIntoFolder(dirs_[s], key_paths_[s], keys_[s], [&](const fs::path& tmp) {
          PanoramaStageReport r;
          fresh_panorama_ = RunPanoramaStage(InputWorkspace().string(), dirs_[1].string(),
                                             tmp.string(), options_.panorama, &r);
          stage_json_["panorama"] = PanoramaResultJson(r);
        });
        break;
      case Stage::kEncode:
        RunEncode();
        break;
    }
  }

  static nlohmann::json PanoramaResultJson(const PanoramaStageReport& r) {
    return {{"width", r.width},
            {"front_coverage", r.front_coverage},
            {"fov_covered_fraction", r.front_fov.covered_fraction},
            {"fov_holes", r.front_fov.num_holes},
            {"fov_largest_hole_fraction", r.front_fov.largest_hole_fraction},
            {"footprint_covered_fraction", r.front_footprint.covered_fraction},
            {"footprint_largest_hole_fraction", r.front_footprint.largest_hole_fraction},
            {"back_nodes", r.fuse.back_nodes_in - r.fuse.back_nodes_redundant +
                               r.fuse.back_nodes_hallucinated}};
  }

  void RunSparse() {
    std::error_code ec;
    // The sparse stage writes OUT.tmp-XXXX and renames it itself.
    sfm::SparseStageOptions sparse = options_.sparse;
    sparse.overwrite = true;
    fs::remove(key_paths_[0], ec);
    const sfm::SparseStageResult r = sfm::RunSparseStage(input_, dirs_[0].string(), sparse);
    io::WriteFileAtomic(key_paths_[0].string(), keys_[0]);
    nlohmann::json skipped = nlohmann::json::array();
    for (const sfm::SkippedPhoto& p : r.skipped)
      skipped.push_back({{"file", p.file}, {"reason", p.reason}});
    stage_json_["sparse"] = {{"input_type", r.input_type},
                             {"photos", r.num_photos},
                             {"registered", r.num_registered},
                             {"unregistered", r.unregistered},
                             {"skipped", skipped},
                             {"points", r.num_points},
                             {"mean_reprojection_error_px", r.mean_reprojection_error_px}};
    if (r.input_type == "video") {
      stage_json_["sparse"]["video"] = {{"frames", r.video.frames_decoded},
                                        {"picked", r.video.picked.size()},
                                        {"blurred", r.video.blurred},
                                        {"rotation_deg", r.video.rotation_deg},
                                        {"frame_selection_seconds", r.video.seconds}};
    }
  }

  // The web package, photo.c3d, and the archival master and previews next
  // to them.
  void RunEncode() {
    std::error_code ec;
    const int s = static_cast<int>(Stage::kEncode);
    const fs::path master = dirs_[2] / "master.exr";
    // The panorama this run made is the master file's content (its round
    // trip is exact); only a cached one is read back.
    StatusOr<TwoLayerPanorama> pano = fresh_panorama_
                                          ? StatusOr<TwoLayerPanorama>(std::move(*fresh_panorama_))
                                          : encoder::ReadMasterFile(master.string());
    fresh_panorama_.reset();
    if (!pano.ok()) throw std::runtime_error(pano.status().ToString());
    encoder::PackageOptions package = encoder::DeliveryPackageOptions();
    package.color_quality = options_.color_quality;
    package.tile_size = options_.tile_size;
    package.num_threads = options_.num_threads;
    encoder::PackageFitOptions fit;
    fit.max_bytes = static_cast<uint64_t>(options_.max_package_kb) * 1024;
    auto fitted = encoder::EncodePackageWithin(*pano, package, fit);
    if (!fitted.ok())
      throw std::runtime_error(fitted.status().message() +
                               (fit.max_bytes > 0 ? " (--max-package-kb)" : ""));
    const encoder::PackageFiles& files = fitted->files;
    const encoder::PackageStats& stats = fitted->stats;
    fs::remove(key_paths_[s], ec);
    Status st = encoder::WritePackageFolder(files, dirs_[s].string());
    if (!st.ok()) throw std::runtime_error(st.ToString());
    if (options_.finish_web_package)
      options_.finish_web_package(dirs_[s].string(), report_.capture_advice);
    st = encoder::WritePackageSingleFile(files, (root_ / "photo.c3d").string());
    if (!st.ok()) throw std::runtime_error(st.ToString());
    io::WriteFileAtomic((root_ / "master.exr").string(), io::ReadFile(master.string()));
    const fs::path preview = dirs_[2] / "preview";
    if (fs::exists(preview, ec)) {
      fs::create_directories(root_ / "preview", ec);
      for (const auto& entry : fs::directory_iterator(preview, ec)) {
        io::WriteFileAtomic((root_ / "preview" / entry.path().filename()).string(),
                            io::ReadFile(entry.path().string()));
      }
    }
    report_.package_bytes = stats.total_bytes;
    io::WriteFileAtomic(key_paths_[s].string(), keys_[s]);
    stage_json_["encode"] = {{"package_bytes", stats.total_bytes},
                             {"files", stats.num_files},
                             {"color_quality", fitted->options.color_quality},
                             {"lossy_normals", fitted->options.lossy_normals}};
  }

  // report.json: the stages (a cached one with the time and results of the
  // run that made it), every option, the capture, skipped files, held-out
  // photos.
  nlohmann::json ReportJson() {
    std::error_code ec;
    nlohmann::json j;
    j["input"] = fs::absolute(input_).string();
    j["seconds_total"] = report_.seconds_total;
    for (size_t s = 0; s < report_.stages.size(); ++s) {
      const StageRun& r = report_.stages[s];
      nlohmann::json e = {{"stage", r.stage},
                          {"cached", r.cached},
                          {"ran", r.ran},
                          {"seconds", r.seconds},
                          {"key", keys_[s]}};
      // A cached stage reports the time it took when it ran, and its results.
      if (r.cached) {
        const nlohmann::json old = PreviousStage(static_cast<int>(s));
        if (old.is_object() && old.contains("seconds") && old["seconds"].is_number()) {
          e["seconds"] = old["seconds"];
          if (previous_.contains("results") && previous_["results"].contains(r.stage) &&
              !stage_json_.contains(r.stage))
            stage_json_[r.stage] = previous_["results"][r.stage];
        }
      }
      j["stages"].push_back(e);
    }
    // Stages after --to keep their entries while their inputs are unchanged.
    for (int s = static_cast<int>(report_.stages.size()); s < kNumStages; ++s) {
      const nlohmann::json old = PreviousStage(s);
      if (!old.is_object()) continue;
      j["stages"].push_back(old);
      const std::string name = StageName(static_cast<Stage>(s));
      if (previous_.contains("results") && previous_["results"].contains(name))
        stage_json_[name] = previous_["results"][name];
    }
    j["results"] = stage_json_;
    // Every option of the stages, as their descriptions give them.
    j["options"] = {{"sparse", util::FieldsJson(options_.sparse)},
                    {"dense", util::FieldsJson(options_.dense)},
                    {"panorama", util::FieldsJson(options_.panorama)}};
    if (!capture_json_.is_null()) j["capture"] = capture_json_;
    // Files of the input the import left out (bad or duplicate), at the top level.
    if (stage_json_.contains("sparse") && stage_json_["sparse"].contains("skipped"))
      j["skipped"] = stage_json_["sparse"]["skipped"];
    if (options_.holdout_every > 0 && fs::exists(dirs_[0] / "sparse", ec)) {
      InputWorkspace();
      j["holdout_every"] = options_.holdout_every;
      j["holdout"] = holdout_;
    }
    return j;
  }

  const std::string input_;
  const PipelineOptions options_;
  const fs::path root_, work_;
  const fs::path dirs_[kNumStages];
  fs::path key_paths_[kNumStages];
  std::string keys_[kNumStages];
  nlohmann::json previous_;
  std::vector<std::string> holdout_;
  fs::path train_dir_;
  PipelineReport report_;
  nlohmann::json stage_json_ = nlohmann::json::object();
  std::optional<TwoLayerPanorama> fresh_panorama_;  // Made by this run's panorama stage.
  nlohmann::json capture_json_;
};

}  // namespace

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
  fs::create_directories(fs::path(out) / "work", ec);
  if (ec)
    throw std::runtime_error(out + ": cannot create the output folder (" + ec.message() + ")");
  return PipelineRun(input, out, options).Run(start);
}

}  // namespace casual3d::pipeline

#include "reconstruct/depth/dense_units.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <filesystem>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "reconstruct/depth/dense_finish.h"
#include "reconstruct/depth/dense_passes.h"
#include "reconstruct/depth/dense_plan_record.h"
#include "reconstruct/depth/dense_schedule.h"
#include "reconstruct/depth/dense_report.h"
#include "reconstruct/io/exr_io.h"
#include "reconstruct/io/file_util.h"

namespace casual3d::depth {
namespace fs = std::filesystem;
namespace {

using Clock = std::chrono::steady_clock;

// OUT/.dense-units/ and its files.
struct UnitFolder {
  fs::path root;
  std::string Path(const char* sub, const std::string& stem, const char* ext) const {
    return (root / sub / (stem + ext)).string();
  }
  std::string Dir(const char* sub) const { return (root / sub).string(); }
};

// What shapes the intermediate files: the options below and the plan (the
// photos, their cameras, depth ranges and neighbours: dense_plan_record.h),
// which units after the first read from here instead of the model.
nlohmann::json PlanRecord(const DensePlan& plan, const DenseOptions& options) {
  nlohmann::json j;
  j["format"] = "casual3d-dense-units";
  j["version"] = "1.1";
  j["plan"] = DensePlanToJson(plan);
  j["working_scale"] = options.working_scale;
  j["num_depths"] = options.sweep.num_depths;
  j["num_neighbors"] = options.num_neighbors;
  j["min_far_over_near"] = options.min_far_over_near;
  j["use_gc_filter"] = options.use_gc_filter;
  j["gc_max_views"] = options.gc.max_views;
  return j;
}

std::string PlanPath(const UnitFolder& units) { return (units.root / "plan.json").string(); }

std::runtime_error OtherPlanError(const UnitFolder& units) {
  return std::runtime_error(PlanPath(units) + ": made from other photos or with other options than this unit's; "
                            "give every unit the same workspace and options, or remove " +
                            units.root.string() + " to start afresh");
}

// plan.json, or null when there is none or it cannot be parsed.
nlohmann::json ReadPlanRecord(const UnitFolder& units) {
  std::error_code ec;
  if (!fs::exists(PlanPath(units), ec)) return nullptr;
  try {
    return nlohmann::json::parse(io::ReadFile(PlanPath(units)));
  } catch (const nlohmann::json::exception&) {
    return nlohmann::json::object();  // Matches no record: refused as another plan.
  }
}

// The plan recorded by an earlier unit, checked against this unit's options
// (`*recorded` true); otherwise the plan made from the workspace (without
// pixels), which CheckOrWritePlan then records or compares.
DensePlan LoadPlan(const std::string& workspace_dir, const DenseOptions& options, const UnitFolder& units,
                   DensePass pass, bool* recorded) {
  *recorded = false;
  if (pass != DensePass::kPlan) {
    const nlohmann::json record = ReadPlanRecord(units);
    if (!record.is_null()) {
      DensePlan plan;
      try {
        plan = DensePlanFromJson(record.at("plan"), (fs::path(workspace_dir) / "images").string());
      } catch (const std::exception&) {
        throw OtherPlanError(units);
      }
      if (PlanRecord(plan, options) != record) throw OtherPlanError(units);
      *recorded = true;
      return plan;
    }
  }
  return PlanDense(workspace_dir, options, /*load_pixels=*/false);
}

// Writes plan.json, or checks that the one there matches.
void CheckOrWritePlan(const UnitFolder& units, const DensePlan& plan, const DenseOptions& options) {
  const nlohmann::json record = PlanRecord(plan, options);
  const nlohmann::json previous = ReadPlanRecord(units);
  if (!previous.is_null()) {
    if (previous != record) throw OtherPlanError(units);
    return;
  }
  io::WriteFileAtomic(PlanPath(units), record.dump(2) + "\n");
}

std::string MissingUnitMessage(const DensePlan& plan, int i, const char* pass, const UnitFolder& units) {
  return "photo " + std::to_string(i) + " (" + plan.ws.views[i].name + ") has no " + pass + " result in " +
         units.root.string() + "; run `casual3d dense ... --pass " + pass + " --photos " + std::to_string(i) +
         "` first";
}

// Photo i's sweep record: its volume's sizes and depth grid, and the time taken.
CostVolume ReadSweepRecord(const DensePlan& plan, int i, const UnitFolder& units, double* seconds) {
  const std::string path = units.Path("sweep", OutputStem(plan.ws.views[i].name), ".json");
  std::error_code ec;
  if (!fs::exists(path, ec)) throw std::runtime_error(MissingUnitMessage(plan, i, "sweep", units));
  const nlohmann::json j = nlohmann::json::parse(io::ReadFile(path));
  CostVolume shell;
  shell.width = j.at("width").get<int>();
  shell.height = j.at("height").get<int>();
  shell.num_labels = j.at("num_labels").get<int>();
  shell.inv_near = j.at("inv_near").get<double>();
  shell.inv_far = j.at("inv_far").get<double>();
  if (seconds) *seconds = j.at("seconds").get<double>();
  return shell;
}

bool HasRecord(const UnitFolder& units, const char* pass, const DensePlan& plan, int i) {
  std::error_code ec;
  return fs::exists(units.Path(pass, OutputStem(plan.ws.views[i].name), ".json"), ec);
}

void SweepUnit(const DensePlan& plan, const DenseOptions& options, const UnitFolder& units,
               const std::vector<int>& todo, int outer, int inner) {
  BufferPool pool(3);
  ForEachPhoto(plan, todo, outer, [&](int i) {
    const auto t0 = Clock::now();
    const std::string stem = OutputStem(plan.ws.views[i].name);
    ImageF wta;
    const CostVolume shell = SweepPhoto(plan, i, options, inner, units.Path("cost", stem, ".cost"), &pool, &wta);
    io::ExrWriteOptions plain;
    plain.compression = io::ExrCompression::kNone;
    io::WriteExr(units.Path("wta", stem, ".exr"), wta, {"Z"}, plain);
    const nlohmann::json record = {{"width", shell.width},       {"height", shell.height},
                                   {"num_labels", shell.num_labels}, {"inv_near", shell.inv_near},
                                   {"inv_far", shell.inv_far},   {"seconds", SecondsSince(t0)}};
    io::WriteFileAtomic(units.Path("sweep", stem, ".json"), record.dump(2) + "\n");
  });
}

void DepthUnit(const DensePlan& plan, const DenseOptions& options, const UnitFolder& units,
               const std::string& out_dir, const std::vector<int>& todo, int outer, int inner) {
  BufferPool pool(3);
  ForEachPhoto(plan, todo, outer, [&](int i) {
    const std::string stem = OutputStem(plan.ws.views[i].name);
    PhotoReport pr = PhotoHeader(plan, i);
    const CostVolume shell = ReadSweepRecord(plan, i, units, &pr.t_sweep);
    std::vector<ImageF> wta(plan.size());
    std::vector<const ImageF*> wta_ptrs(plan.size());
    for (int j : SweepsNeeded(plan, options, i)) {
      ReadSweepRecord(plan, j, units, nullptr);
      wta[j] = ReadDepthMap(units.Dir("wta"), OutputStem(plan.ws.views[j].name));
    }
    for (int j = 0; j < plan.size(); ++j) wta_ptrs[j] = &wta[j];
    const ImageF ground_truth =
        options.ground_truth_dir.empty() ? ImageF() : ReadDepthMap(options.ground_truth_dir, stem);
    const ImageF depth = DepthPhoto(plan, i, options, inner, wta_ptrs, shell, units.Path("cost", stem, ".cost"),
                                    ground_truth, out_dir, &pool, &pr);
    io::ExrWriteOptions plain;
    plain.compression = io::ExrCompression::kNone;
    io::WriteExr(units.Path("depth", stem, ".exr"), depth, {"Z"}, plain);
    io::WriteFileAtomic(units.Path("depth", stem, ".json"), PhotoReportToJson(pr).dump(2) + "\n");
    // Only this pass reads the photo's cost cache, and its record now says
    // it is done: the cache's gigabyte goes before the other photos' sweeps
    // need the disk.
    std::error_code ec;
    fs::remove(units.Path("cost", stem, ".cost"), ec);
  });
}

// Throws unless every photo's depth unit is done.
void CheckDepthUnitsDone(const DensePlan& plan, const UnitFolder& units) {
  const int n = plan.size();
  std::vector<int> missing;
  for (int i = 0; i < n; ++i)
    if (!HasRecord(units, "depth", plan, i)) missing.push_back(i);
  if (!missing.empty()) {
    std::string list;
    for (int i : missing) list += (list.empty() ? "" : ",") + std::to_string(i);
    throw std::runtime_error(units.root.string() + ": " + std::to_string(missing.size()) + " of " +
                             std::to_string(n) + " photos have no depth result (photos " + list +
                             "); run `casual3d dense ... --pass depth --photos " + list + "` first");
  }
}

DenseReport FinishUnit(const DensePlan& plan, const DenseOptions& options, const UnitFolder& units,
                       const std::string& out_dir, Clock::time_point start, double seconds_load) {
  const int n = plan.size();
  std::vector<PhotoReport> photos(n);
  std::vector<CostVolume> shells(n);
  for (int i = 0; i < n; ++i) {
    const std::string stem = OutputStem(plan.ws.views[i].name);
    shells[i] = ReadSweepRecord(plan, i, units, nullptr);
    photos[i] = PhotoReportFromJson(nlohmann::json::parse(io::ReadFile(units.Path("depth", stem, ".json"))));
  }
  // The maps, the photos and the ground truth are read when pass 3 needs
  // them, so that the unit needs the memory of the photos in flight and
  // their neighbours whatever the capture's size.
  const auto owned = [](ImageF image) { return std::make_shared<const ImageF>(std::move(image)); };
  FinishInputs inputs;
  inputs.depth = [&](int i) { return owned(ReadDepthMap(units.Dir("depth"), OutputStem(plan.ws.views[i].name))); };
  inputs.gray_full = [&](int i) { return owned(ReadViewGrayFull(plan.ws, i)); };
  inputs.ground_truth = [&](int i) {
    return owned(ReadDepthMap(options.ground_truth_dir, OutputStem(plan.ws.views[i].name)));
  };
  DenseReport report =
      FinishDense(plan, options, inputs, std::move(photos), shells, out_dir, start, seconds_load);
  // dense.json exists: the stage is complete and its intermediates are
  // spent, as are the temporary files of units killed while writing.
  std::error_code ec;
  fs::remove_all(units.root, ec);
  for (const char* sub : {"depth", "confidence", "envelope"})
    for (const auto& e : fs::directory_iterator(fs::path(out_dir) / sub, ec))
      if (e.path().filename().string().find(".tmp-") != std::string::npos) fs::remove(e.path(), ec);
  return report;
}

}  // namespace

bool DensePassFromName(const std::string& name, DensePass* pass) {
  if (name == "plan") *pass = DensePass::kPlan;
  else if (name == "sweep") *pass = DensePass::kSweep;
  else if (name == "depth") *pass = DensePass::kDepth;
  else if (name == "finish") *pass = DensePass::kFinish;
  else return false;
  return true;
}

std::vector<int> ParsePhotoList(const std::string& text) {
  const auto bad = [&](const std::string& item) {
    return std::invalid_argument("--photos " + text + ": '" + item +
                                 "' is not an index or an increasing range (expected e.g. 0,3,5-9)");
  };
  // A whole string of digits as an int; false otherwise.
  const auto parse = [](const std::string& s, int* value) {
    const char* end = s.data() + s.size();
    const auto r = std::from_chars(s.data(), end, *value);
    return !s.empty() && r.ec == std::errc() && r.ptr == end && *value >= 0;
  };
  std::vector<int> out;
  size_t pos = 0;
  while (pos <= text.size()) {
    const size_t comma = std::min(text.find(',', pos), text.size());
    const std::string item = text.substr(pos, comma - pos);
    const size_t dash = item.find('-');
    int first = 0, last = 0;
    if (!parse(item.substr(0, dash), &first)) throw bad(item);
    last = first;
    if (dash != std::string::npos && !parse(item.substr(dash + 1), &last)) throw bad(item);
    if (last < first || last >= 1000000) throw bad(item);
    for (int i = first; i <= last; ++i) out.push_back(i);
    pos = comma + 1;
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

DenseUnitResult RunDenseUnit(const std::string& workspace_dir, const std::string& out_dir,
                             const DenseOptions& options, DensePass pass, const std::vector<int>& photos) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  if (!options.ground_truth_dir.empty() && !fs::is_directory(options.ground_truth_dir))
    throw std::runtime_error(options.ground_truth_dir + ": ground-truth folder does not exist");
  const auto start = Clock::now();
  const UnitFolder units{fs::path(out_dir) / ".dense-units"};
  // Pixels are loaded below, only those of the photos this unit reads.
  bool recorded = false;
  DensePlan plan = LoadPlan(workspace_dir, options, units, pass, &recorded);
  const int n = plan.size();
  for (int i : photos)
    if (i >= n)
      throw std::invalid_argument("--photos: no photo " + std::to_string(i) + " (the workspace has " +
                                  std::to_string(n) + " photos, numbered 0-" + std::to_string(n - 1) + ")");

  DenseUnitResult result;
  for (const DenseView& v : plan.ws.views) result.photos.push_back(v.name);
  // The photos of this unit not yet done (their record is written last),
  // and what they need, checked before anything is written.
  std::vector<int> todo;
  if (pass == DensePass::kSweep || pass == DensePass::kDepth) {
    for (int i : photos.empty() ? AllPhotos(n) : photos) {
      if (HasRecord(units, pass == DensePass::kSweep ? "sweep" : "depth", plan, i)) {
        ++result.skipped;
      } else {
        todo.push_back(i);
      }
    }
  }
  if (pass == DensePass::kDepth)
    for (int i : todo) {
      for (int j : SweepsNeeded(plan, options, i))
        if (!HasRecord(units, "sweep", plan, j)) throw std::runtime_error(MissingUnitMessage(plan, j, "sweep", units));
      // A depth unit deletes its cost cache after its record; a cache gone
      // without that record (the record removed by hand) needs a new sweep.
      std::error_code ec;
      const std::string stem = OutputStem(plan.ws.views[i].name);
      if (!fs::exists(units.Path("cost", stem, ".cost"), ec))
        throw std::runtime_error(units.Path("cost", stem, ".cost") + ": cost cache missing; delete " +
                                 units.Path("sweep", stem, ".json") + " and run `casual3d dense ... --pass sweep " +
                                 "--photos " + std::to_string(i) + "` again");
    }
  if (pass == DensePass::kFinish) CheckDepthUnitsDone(plan, units);

  const int threads = base::ResolveThreads(options.num_threads);
  if (pass == DensePass::kPlan) {
    // Every photo must decode at its camera's size; one at a time, so that
    // the plan of a large capture needs the memory of one photo.
    for (int i = 0; i < n; ++i) CheckViewPhoto(plan.ws, i);
  } else if (pass != DensePass::kFinish) {  // The finish unit reads its photos when it needs them.
    ForEachPhoto(plan, PhotosRead(plan, todo), threads, [&](int i) { LoadViewPixels(&plan.ws, i); });
  }
  const double seconds_load = SecondsSince(start);

  CreateDenseOutputFolders(out_dir, options);
  for (const char* sub : {"cost", "wta", "sweep", "depth"}) io::CreateDirectories(units.Dir(sub));
  if (!recorded) CheckOrWritePlan(units, plan, options);
  if (pass == DensePass::kPlan) {
    DenseSchedule schedule = ScheduleDense(plan, options);
    result.sweep_order = std::move(schedule.sweep_order);
    result.needs = std::move(schedule.needs);
    return result;
  }
  if (pass == DensePass::kFinish) {
    result.report = FinishUnit(plan, options, units, out_dir, start, seconds_load);
    result.ran = n;
    return result;
  }
  result.ran = static_cast<int>(todo.size());
  if (todo.empty()) return result;
  const int outer = std::min<int>(threads, static_cast<int>(todo.size()));
  const int inner = std::max(1, threads / outer);
  if (pass == DensePass::kSweep) {
    SweepUnit(plan, options, units, todo, outer, inner);
  } else {
    DepthUnit(plan, options, units, out_dir, todo, outer, inner);
  }
  return result;
}

}  // namespace casual3d::depth

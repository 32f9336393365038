#pragma once

// `casual3d reconstruct`: photos in, web-ready 3D photo out. Runs the stages
// sparse (reconstruct/sfm), dense (reconstruct/depth), panorama (warp, stitch,
// fuse, normals: panorama_stage.h) and encode (encoder/), caching each stage's
// output under OUT/work keyed by its inputs and options, so that a rerun after
// a crash or a kill resumes at the first stage whose output is missing or
// stale, and nothing already computed is lost.
//
// Output folder:
//   OUT/web/            the web package with index.html and the viewer: deployable as is
//   OUT/photo.c3d       the same package as one file
//   OUT/master.exr      the lossless two-layer panorama (archival form)
//   OUT/preview/        stitched colour, depth, normals and labels as PNG
//   OUT/report.json     timings and statistics of every stage, with the key of
//                       its cache; a cached stage keeps the figures of the run
//                       that computed it; "capture": the capture's shape and
//                       advice (capture_shape.h); "options": every option of
//                       the sparse, dense and panorama stages
//   OUT/work/{sparse,dense,panorama}/ and OUT/work/<stage>.key   stage caches
//
// Cache key: a stage's key is the SHA-256 (hex) of its version (kStageVersions
// in pipeline.cc), the previous stage's key (the sparse stage: the input's
// canonical path and the names, sizes and times of its files) and the text
// util::FieldsKeyText makes of the stage's options: one "path=value" line per
// field of the options struct and the structs nested in it, in the order of
// its description (reconstruct/util/options_fields.h), for example
// "mrf.max_iterations=6" or "sweep.texture_color_sigma=0.1"; numbers in the
// shortest form that reads back to the same value, booleans as true/false,
// strings quoted. Thread counts (and the sparse stage's overwrite) are left
// out: they do not change what a stage writes. The dense key adds
// "holdout N" when photos are held out; the encode key the colour quality
// and tile size.

#include <functional>
#include <string>
#include <vector>

#include "reconstruct/depth/dense_stage.h"
#include "reconstruct/pipeline/panorama_stage.h"
#include "reconstruct/sfm/sparse_stage.h"

namespace casual3d::pipeline {

enum class Stage : int { kSparse = 0, kDense = 1, kPanorama = 2, kEncode = 3 };
constexpr int kNumStages = 4;
const char* StageName(Stage stage);
// Parses "sparse", "dense", "panorama" or "encode"; false otherwise.
bool StageFromName(const std::string& name, Stage* stage);

struct PipelineOptions {
  sfm::SparseStageOptions sparse;
  depth::DenseOptions dense;
  PanoramaStageOptions panorama;
  // Encoding of the web package (encoder/package_writer.h), by its main knobs.
  float color_quality = 90.0f;  // Lossy WebP quality of colour tiles, [0, 100].
  int tile_size = 512;          // Tile side, pixels, [16, 4096].
  // The whole package at most this many KB (encoder/package_fit.h: lossy
  // normals, then colour quality down to 75); 0 = no budget.
  int max_package_kb = 0;
  // Run the stages from `from` to `to` (inclusive). Stages before `from` must
  // have their outputs in the cache.
  Stage from = Stage::kSparse;
  Stage to = Stage::kEncode;
  bool force = false;  // Recompute the selected stages even if cached.
  // Held-out views (holdout.h): > 0 registers every photo but builds the 3D
  // photo without photos 0, n, 2n, ... of the sorted names (listed in
  // report.json as "holdout"), for `casual3d evaluate`. [0, 1000]; 0 = none.
  int holdout_every = 0;
  int num_threads = 0; // 0 = all cores; passed to every stage.
  // Called with OUT/web after the package is written there, and the
  // capture's advice (capture_shape.h; empty if not measured): the
  // command-line program adds the viewer page, its files and an info panel
  // with the advice; may be empty.
  std::function<void(const std::string& web_dir, const std::vector<std::string>& capture_advice)>
      finish_web_package;

  Status Check() const;
};

struct StageRun {
  std::string stage;
  bool cached = false;   // Skipped because its cached output was current.
  bool ran = false;
  double seconds = 0.0;
};

struct PipelineReport {
  std::vector<StageRun> stages;
  double seconds_total = 0.0;
  std::string web_dir;     // OUT/web, when the encode stage ran or was cached.
  uint64_t package_bytes = 0;
  // The capture's shape in plain words (capture_shape.h), the description
  // first; report.json's "capture" holds the measures.
  std::vector<std::string> capture_advice;
};

// Runs the pipeline on `input` (a folder of photos or a COLMAP workspace) into
// `out`. Throws std::invalid_argument for bad options and std::runtime_error
// with one clear line for everything else.
PipelineReport RunPipeline(const std::string& input, const std::string& out,
                           const PipelineOptions& options);

}  // namespace casual3d::pipeline

#include "reconstruct/depth/dense_report.h"

#include "reconstruct/io/file_util.h"
#include "reconstruct/util/options_json.h"

namespace casual3d::depth {

NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(StageQuality, stage, completeness, precision)

void SummariseDenseReport(DenseReport* report) {
  const size_t n = report->photos.size();
  report->cross_view_consistency = 0.0;
  for (const PhotoReport& pr : report->photos) report->cross_view_consistency += pr.cross_view_consistency / n;
  long long weight = 0, pixels = 0, observed = 0;
  for (const PhotoReport& pr : report->photos) {
    if (!pr.evaluated) continue;
    pixels += pr.pixels;
    observed += pr.observed_pixels;
    report->median_rel_error_observed += pr.median_rel_error_observed * pr.observed_pixels;
    report->within_3pct_observed += pr.within_3pct_observed * pr.observed_pixels;
    report->near_floaters_observed += pr.near_floaters_observed * pr.observed_pixels;
    const long long px = static_cast<long long>(pr.width) * pr.height;
    report->evaluated = true;
    report->median_rel_error += pr.median_rel_error * px;
    report->within_3pct += pr.within_3pct * px;
    report->near_floaters += pr.near_floaters * px;
    report->within_half_label += pr.within_half_label * px;
    report->within_two_labels += pr.within_two_labels * px;
    weight += px;
  }
  if (weight > 0) {
    report->median_rel_error /= weight;
    report->within_3pct /= weight;
    report->near_floaters /= weight;
    report->within_half_label /= weight;
    report->within_two_labels /= weight;
  }
  if (observed > 0) {
    report->observed_fraction = static_cast<double>(observed) / pixels;
    report->median_rel_error_observed /= observed;
    report->within_3pct_observed /= observed;
    report->near_floaters_observed /= observed;
  }
}

void WriteDenseJson(const std::string& path, const DenseReport& report, const DenseOptions& options) {
  nlohmann::json j;
  j["format"] = "casual3d-dense-report";
  j["version"] = "1.0";
  j["seconds_total"] = report.seconds_total;
  j["seconds_load"] = report.seconds_load;
  j["peak_rss_bytes"] = report.peak_rss_bytes;
  j["use_near_envelope"] = options.use_near_envelope;
  j["use_gc_filter"] = options.use_gc_filter;
  j["num_depths"] = options.sweep.num_depths;
  j["working_scale"] = options.working_scale;
  j["cross_view_consistency"] = report.cross_view_consistency;
  j["options"] = util::FieldsJson(options);  // Every option (dense_stage.h).
  if (report.evaluated) {
    j["accuracy"] = {{"median_rel_error", report.median_rel_error},
                     {"within_3pct", report.within_3pct},
                     {"near_floaters", report.near_floaters},
                     {"within_half_label", report.within_half_label},
                     {"within_two_labels", report.within_two_labels},
                     {"observed_fraction", report.observed_fraction},
                     {"median_rel_error_observed", report.median_rel_error_observed},
                     {"within_3pct_observed", report.within_3pct_observed},
                     {"near_floaters_observed", report.near_floaters_observed}};
  }
  for (const PhotoReport& pr : report.photos) {
    nlohmann::json p;
    p["name"] = pr.name;
    p["neighbors"] = pr.neighbors;
    p["near_m"] = pr.near_m;
    p["far_m"] = pr.far_m;
    p["size"] = {pr.width, pr.height};
    p["work_size"] = {pr.work_width, pr.work_height};
    p["num_labels"] = pr.num_labels;
    p["anchors"] = {{"wta", pr.anchors[0]}, {"gc", pr.anchors[1]}, {"median", pr.anchors[2]},
                    {"bilateral", pr.anchors[3]}};
    p["cg_iterations"] = pr.cg_iterations;
    p["mrf_energy"] = pr.mrf_energy;
    p["mrf_iterations"] = pr.mrf_iterations;
    p["cross_view_consistency"] = pr.cross_view_consistency;
    // "flat" is part of "mrf", "fullres" of "upsample_write".
    p["seconds"] = {{"sweep", pr.t_sweep},     {"envelope", pr.t_envelope}, {"mrf", pr.t_mrf},
                    {"flat", pr.t_flat},       {"refine", pr.t_refine},     {"upsample_write", pr.t_upsample},
                    {"fullres", pr.t_fullres}};
    p["flat_regions"] = {{"groups", pr.flat_groups}, {"fitted", pr.flat_fitted}, {"pixels", pr.flat_pixels}};
    p["relabelled_pixels"] = pr.relabelled;
    p["free_space"] = {{"seen_through", pr.seen_through}, {"moved_back", pr.moved_back}, {"seconds", pr.t_visibility}};
    p["refined_pixels"] = pr.refined;
    if (pr.evaluated) {
      p["accuracy"] = {{"median_rel_error", pr.median_rel_error}, {"within_3pct", pr.within_3pct},
                       {"near_floaters", pr.near_floaters}, {"sky_near", pr.sky_near},
                       {"within_half_label", pr.within_half_label}, {"within_two_labels", pr.within_two_labels},
                       {"observed_fraction", pr.pixels > 0 ? static_cast<double>(pr.observed_pixels) / pr.pixels : 0.0},
                       {"median_rel_error_observed", pr.median_rel_error_observed},
                       {"within_3pct_observed", pr.within_3pct_observed},
                       {"near_floaters_observed", pr.near_floaters_observed}};
      for (const StageQuality& s : pr.stages)
        p["anchor_quality"][s.stage] = {{"completeness", s.completeness}, {"precision", s.precision}};
      p["envelope_quality"] = {{"error", pr.envelope_error}, {"tightness", pr.envelope_tightness}};
    }
    j["photos"].push_back(p);
  }
  io::WriteFileAtomic(path, j.dump(2) + "\n");
}

// Every field, so that a photo's report crosses from one unit to the next unchanged.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(PhotoReport, name, neighbors, near_m, far_m, width, height, work_width,
                                   work_height, num_labels, anchors, cg_iterations, mrf_energy,
                                   cross_view_consistency, mrf_iterations, t_sweep, t_envelope, t_mrf, t_refine,
                                   t_upsample, t_flat, t_fullres, flat_groups, flat_fitted, flat_pixels,
                                   relabelled, refined, seen_through, moved_back, t_visibility, evaluated,
                                   median_rel_error, within_3pct, near_floaters, sky_near, within_half_label,
                                   within_two_labels, pixels, observed_pixels, median_rel_error_observed,
                                   within_3pct_observed, near_floaters_observed, stages, envelope_error,
                                   envelope_tightness)

nlohmann::json PhotoReportToJson(const PhotoReport& report) { return report; }

PhotoReport PhotoReportFromJson(const nlohmann::json& json) { return json.get<PhotoReport>(); }

}  // namespace casual3d::depth

#include "reconstruct/pipeline/panorama_report.h"

#include <nlohmann/json.hpp>

namespace casual3d::pipeline {
namespace {

nlohmann::json CoverageJson(const CoverageStats& c) {
  return nlohmann::json{{"fov_pixels", c.fov_pixels},
                        {"fov_steradians", c.fov_steradians},
                        {"covered_fraction", c.covered_fraction},
                        {"holes", c.num_holes},
                        {"hole_pixels", c.hole_pixels},
                        {"largest_hole_pixels", c.largest_hole_pixels},
                        {"largest_hole_fraction", c.largest_hole_fraction},
                        {"interior_holes", c.num_interior_holes},
                        {"largest_interior_hole_fraction", c.largest_interior_hole_fraction},
                        {"reference_depth_m", c.reference_depth_m}};
}

}  // namespace

std::string PanoramaReportJson(const PanoramaStageReport& report,
                               const PanoramaStageOptions& options, const ViewHints& hints) {
  nlohmann::json j;
  j["photos"] = report.num_photos;
  j["width"] = report.width;
  j["height"] = report.height;
  j["back_layer"] = options.back_layer;
  j["sky_depth_m"] = report.sky_depth_m;
  j["front_coverage"] = report.front_coverage;
  j["front_fov"] = CoverageJson(report.front_fov);
  j["view"] = nlohmann::json::parse(SerializeViewHints(hints));
  j["front_gaps_filled"] = report.front_gaps_filled;
  auto seam_json = [](const stitch::SeamBlendStats& st) {
    return nlohmann::json{{"pairs_with_target", st.pairs_with_target},
                          {"pairs_cut", st.pairs_cut},
                          {"iterations", st.iterations},
                          {"relative_residual", st.relative_residual}};
  };
  j["seam_blend"] = {{"front", seam_json(report.seam_blend_front)},
                     {"back", seam_json(report.seam_blend_back)}};
  j["front_footprint"] = CoverageJson(report.front_footprint);
  j["fuse"] = {{"front_nodes", report.fuse.front_nodes},
               {"back_nodes_in", report.fuse.back_nodes_in},
               {"back_nodes_redundant", report.fuse.back_nodes_redundant},
               {"back_nodes_hallucinated", report.fuse.back_nodes_hallucinated},
               {"front_nodes_relabelled", report.fuse.front_nodes_relabelled},
               {"links", report.fuse.links}};
  j["seal"] = {{"enabled", options.seal_tears},
               {"open_quads_before", report.seal.open_quads_before},
               {"open_quads_after", report.seal.open_quads_after},
               {"back_open_quads_before", report.seal.back_open_quads_before},
               {"back_open_quads_after", report.seal.back_open_quads_after},
               {"front_surface_open_quads_before", report.seal.front_surface_open_quads_before},
               {"front_surface_open_quads_after", report.seal.front_surface_open_quads_after},
               {"links_made", report.seal.links_made},
               {"back_nodes_added", report.seal.back_nodes_added}};
  j["normals"] = {{"nodes", report.normals.nodes}, {"sky_nodes", report.normals.sky_nodes}};
  j["seconds"] = {{"load", report.seconds_load},
                  {"warp", report.seconds_warp},
                  {"stitch_front", report.seconds_stitch_front},
                  {"stitch_back", report.seconds_stitch_back},
                  {"fuse", report.seconds_fuse},
                  {"normals", report.seconds_normals},
                  {"write", report.seconds_write},
                  {"total", report.seconds_total}};
  return j.dump(2) + "\n";
}

}  // namespace casual3d::pipeline

#include "reconstruct/depth/dense_plan_record.h"

#include <stdexcept>

namespace casual3d::depth {
namespace {

nlohmann::json CameraToJson(const PinholeCamera& c) {
  nlohmann::json j = {{"width", c.width}, {"height", c.height}, {"fx", c.fx},
                      {"fy", c.fy},       {"cx", c.cx},         {"cy", c.cy}};
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) j["R"].push_back(c.R(r, k));
    j["t"].push_back(c.t(r));
  }
  return j;
}

PinholeCamera CameraFromJson(const nlohmann::json& j) {
  PinholeCamera c;
  c.width = j.at("width").get<int>();
  c.height = j.at("height").get<int>();
  c.fx = j.at("fx").get<double>();
  c.fy = j.at("fy").get<double>();
  c.cx = j.at("cx").get<double>();
  c.cy = j.at("cy").get<double>();
  const auto& R = j.at("R");
  const auto& t = j.at("t");
  if (R.size() != 9 || t.size() != 3) throw std::runtime_error("a camera needs 9 rotation and 3 translation values");
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) c.R(r, k) = R.at(3 * r + k).get<double>();
    c.t(r) = t.at(r).get<double>();
  }
  return c;
}

// `list` as view indices, each in [0, n).
std::vector<int> Indices(const nlohmann::json& list, int n) {
  std::vector<int> out = list.get<std::vector<int>>();
  for (int i : out)
    if (i < 0 || i >= n) throw std::runtime_error("neighbour index " + std::to_string(i) + " out of range");
  return out;
}

}  // namespace

nlohmann::json DensePlanToJson(const DensePlan& plan) {
  nlohmann::json views = nlohmann::json::array();
  for (int i = 0; i < plan.size(); ++i) {
    const DenseView& v = plan.ws.views[i];
    views.push_back({{"name", v.name},
                     {"full_width", v.full_width},
                     {"full_height", v.full_height},
                     {"camera", CameraToJson(v.camera)},
                     {"camera_full", CameraToJson(v.camera_full)},
                     {"near_m", v.range.near_m},
                     {"far_m", v.range.far_m},
                     {"num_labels", plan.num_labels[i]},
                     {"ranked_neighbors", plan.ws.ranked_neighbors[i]},
                     {"swept", plan.swept[i]}});
  }
  return {{"views", views}, {"diag_ratio", plan.diag_ratio}};
}

DensePlan DensePlanFromJson(const nlohmann::json& j, const std::string& images_dir) {
  DensePlan plan;
  try {
    const auto& views = j.at("views");
    const int n = static_cast<int>(views.size());
    plan.ws.images_dir = images_dir;
    for (const auto& e : views) {
      DenseView v;
      v.name = e.at("name").get<std::string>();
      v.full_width = e.at("full_width").get<int>();
      v.full_height = e.at("full_height").get<int>();
      v.camera = CameraFromJson(e.at("camera"));
      v.camera_full = CameraFromJson(e.at("camera_full"));
      v.range.near_m = e.at("near_m").get<double>();
      v.range.far_m = e.at("far_m").get<double>();
      plan.ws.views.push_back(std::move(v));
      plan.num_labels.push_back(e.at("num_labels").get<int>());
      plan.ws.ranked_neighbors.push_back(Indices(e.at("ranked_neighbors"), n));
      plan.swept.push_back(Indices(e.at("swept"), n));
    }
    plan.diag_ratio = j.at("diag_ratio").get<double>();
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(std::string("not a dense plan record: ") + e.what());
  }
  return plan;
}

}  // namespace casual3d::depth

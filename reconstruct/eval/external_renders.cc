#include "reconstruct/eval/external_renders.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

namespace casual3d::eval {

namespace fs = std::filesystem;

std::string ExternalRenderName(const std::string& name) {
  std::string flat = fs::path(name).replace_extension(".png").string();
  for (char& c : flat)
    if (c == '/' || c == '\\') c = '_';
  return flat;
}

void GlMatrices(const render::PinholeView& view, double near, double far, double view_matrix[16],
                double projection_matrix[16]) {
  // Eye frame = COLMAP's camera frame with Y and Z negated.
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      const double sign = r == 0 || r == 3 ? 1.0 : -1.0;
      double v = 0.0;
      if (r < 3) v = sign * (c < 3 ? view.rotation(r, c) : view.translation(r));
      else v = c == 3 ? 1.0 : 0.0;
      view_matrix[4 * c + r] = v;
    }
  // x_ndc = 2 u / W - 1 and y_ndc = 1 - 2 v / H for the pixel (u, v) of
  // u = fx X / Z + cx, v = fy Y / Z + cy (camera frame, row 0 at the top).
  const double w = view.width, h = view.height;
  double p[4][4] = {{2 * view.fx / w, 0, 1 - 2 * view.cx / w, 0},
                    {0, 2 * view.fy / h, 2 * view.cy / h - 1, 0},
                    {0, 0, -(far + near) / (far - near), -2 * far * near / (far - near)},
                    {0, 0, -1, 0}};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) projection_matrix[4 * c + r] = p[r][c];
}

std::string RephotoCamerasJson(const std::vector<NamedView>& views, double near, double far) {
  if (!(near > 0 && far > near && std::isfinite(far)))
    throw std::invalid_argument("rephotography cameras: clip planes near " + std::to_string(near) +
                                ", far " + std::to_string(far) + " must satisfy 0 < near < far");
  nlohmann::json cameras = nlohmann::json::array();
  for (const NamedView& nv : views) {
    if (Status s = nv.view.Check(); !s.ok())
      throw std::invalid_argument("rephotography camera of " + nv.name + ": " + s.message());
    double vm[16], pm[16];
    GlMatrices(nv.view, near, far, vm, pm);
    cameras.push_back({{"name", nv.name},
                       {"image", ExternalRenderName(nv.name)},
                       {"width", nv.view.width},
                       {"height", nv.view.height},
                       {"fx", nv.view.fx},
                       {"fy", nv.view.fy},
                       {"cx", nv.view.cx},
                       {"cy", nv.view.cy},
                       {"view_matrix", std::vector<double>(vm, vm + 16)},
                       {"projection_matrix", std::vector<double>(pm, pm + 16)}});
  }
  const nlohmann::json doc = {{"format", "casual3d-rephoto-cameras"},
                              {"version", 1},
                              {"frame", "panorama"},
                              {"near", near},
                              {"far", far},
                              {"cameras", cameras}};
  return doc.dump(1) + "\n";
}

std::vector<NamedView> ReadRephotoCameras(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read the cameras (write them with `casual3d evaluate --write-cameras`)");
  std::vector<NamedView> views;
  try {
    const nlohmann::json doc = nlohmann::json::parse(in);
    if (doc.value("format", "") != "casual3d-rephoto-cameras") throw std::runtime_error("format is not casual3d-rephoto-cameras");
    for (const auto& c : doc.at("cameras")) {
      NamedView nv;
      nv.name = c.at("name").get<std::string>();
      const auto& m = c.at("view_matrix");
      // GlMatrices' eye frame back to the camera frame: rows 1 and 2 negated.
      for (int r = 0; r < 3; ++r) {
        const double sign = r == 0 ? 1.0 : -1.0;
        for (int col = 0; col < 3; ++col) nv.view.rotation(r, col) = sign * m.at(4 * col + r).get<double>();
        nv.view.translation(r) = sign * m.at(12 + r).get<double>();
      }
      nv.view.width = c.at("width");
      nv.view.height = c.at("height");
      nv.view.fx = c.at("fx");
      nv.view.fy = c.at("fy");
      nv.view.cx = c.at("cx");
      nv.view.cy = c.at("cy");
      if (Status s = nv.view.Check(); !s.ok()) throw std::runtime_error("camera of " + nv.name + ": " + s.message());
      views.push_back(std::move(nv));
    }
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": not a cameras file of `casual3d evaluate --write-cameras`: " + e.what());
  }
  if (views.empty()) throw std::runtime_error(path + ": no cameras");
  return views;
}

ExternalRender ReadExternalRender(const std::string& dir, const std::string& name, int width,
                                  int height) {
  const fs::path file = fs::path(dir) / ExternalRenderName(name);
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    throw std::runtime_error(file.string() + ": no rendering of photo " + name +
                             " (render every camera of the cameras file into this folder)");
  const cv::Mat m = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
  if (m.empty() || m.depth() != CV_8U || (m.channels() != 3 && m.channels() != 4))
    throw std::runtime_error(file.string() + ": not an 8-bit RGB or RGBA image");
  if (m.cols != width || m.rows != height)
    throw std::runtime_error(file.string() + ": " + std::to_string(m.cols) + "x" +
                             std::to_string(m.rows) + " pixels, but photo " + name +
                             " is evaluated at " + std::to_string(width) + "x" +
                             std::to_string(height));
  ExternalRender out{Image8(width, height, 3), Image8(width, height, 1)};
  const int c = m.channels();
  for (int y = 0; y < height; ++y) {
    const uint8_t* row = m.ptr<uint8_t>(y);
    for (int x = 0; x < width; ++x) {
      const uint8_t* px = row + c * x;  // BGR(A)
      const bool covered = c == 3 || px[3] > 0;
      out.mask.at(x, y) = covered ? 255 : 0;
      for (int k = 0; k < 3; ++k) out.color.at(x, y, k) = covered ? px[2 - k] : 0;
    }
  }
  return out;
}

}  // namespace casual3d::eval

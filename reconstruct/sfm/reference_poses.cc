#include "reconstruct/sfm/reference_poses.h"

#include <dirent.h>

#include <algorithm>

#include <Eigen/SVD>
#include <cmath>
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "reconstruct/io/file_util.h"

namespace casual3d::sfm {
namespace {

uint32_t ReadLittleEndian(const std::string& bytes, size_t offset, int num_bytes) {
  uint32_t v = 0;
  for (int i = num_bytes - 1; i >= 0; --i) {
    v = (v << 8) | static_cast<unsigned char>(bytes[offset + i]);
  }
  return v;
}

geometry::Pose PoseFromCameraToWorld(const Eigen::Matrix3d& R_c2w, const Eigen::Vector3d& centre) {
  geometry::Pose pose;
  const Eigen::Matrix3d R_w2c = R_c2w.transpose();
  pose.rotation = Eigen::Quaterniond(R_w2c).normalized();
  pose.translation = -R_w2c * centre;
  return pose;
}

bool IsRotation(const Eigen::Matrix3d& R, double tol) {
  return (R * R.transpose() - Eigen::Matrix3d::Identity()).norm() < tol &&
         std::abs(R.determinant() - 1.0) < tol;
}

}  // namespace

NpyArray ReadNpy(const std::string& path) {
  const std::string bytes = io::ReadFile(path);
  if (bytes.size() < 10 || bytes.compare(0, 6, "\x93NUMPY") != 0) {
    throw std::runtime_error(path + ": not a NumPy .npy file (bad magic)");
  }
  const int major = static_cast<unsigned char>(bytes[6]);
  if (major < 1 || major > 3) {
    throw std::runtime_error(path + ": unsupported .npy version " + std::to_string(major));
  }
  const int len_bytes = major == 1 ? 2 : 4;
  const size_t header_len = ReadLittleEndian(bytes, 8, len_bytes);
  const size_t data_start = 8 + len_bytes + header_len;
  if (bytes.size() < data_start) throw std::runtime_error(path + ": truncated .npy header");
  const std::string header = bytes.substr(8 + len_bytes, header_len);

  std::smatch m;
  if (!std::regex_search(header, m, std::regex(R"re('descr'\s*:\s*'([<>|=]?)([a-z])(\d+)')re"))) {
    throw std::runtime_error(path + ": .npy header has no readable 'descr'");
  }
  const std::string order = m[1], kind = m[2];
  const int item_size = std::stoi(m[3]);
  if (order == ">" || kind != "f" || (item_size != 4 && item_size != 8)) {
    throw std::runtime_error(path + ": unsupported .npy dtype " + m.str(0) +
                             " (little-endian float32 or float64 only)");
  }
  if (std::regex_search(header, std::regex(R"re('fortran_order'\s*:\s*True)re"))) {
    throw std::runtime_error(path + ": Fortran-ordered .npy arrays are not supported");
  }
  if (!std::regex_search(header, m, std::regex(R"re('shape'\s*:\s*\(([^)]*)\))re"))) {
    throw std::runtime_error(path + ": .npy header has no 'shape'");
  }
  NpyArray array;
  size_t count = 1;
  const std::string dims = m[1];
  std::regex number(R"(\d+)");
  for (auto it = std::sregex_iterator(dims.begin(), dims.end(), number);
       it != std::sregex_iterator(); ++it) {
    array.shape.push_back(std::stoull(it->str()));
    count *= array.shape.back();
  }
  if (bytes.size() - data_start < count * item_size) {
    throw std::runtime_error(path + ": truncated .npy data (" + std::to_string(count) +
                             " values expected)");
  }
  array.data.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const char* p = bytes.data() + data_start + i * item_size;
    if (item_size == 8) {
      double v;
      std::memcpy(&v, p, 8);
      array.data[i] = v;
    } else {
      float v;
      std::memcpy(&v, p, 4);
      array.data[i] = v;
    }
  }
  return array;
}

std::map<std::string, ReferenceCamera> ReadLlffPosesBounds(
    const std::string& path, const std::vector<std::string>& image_names) {
  const NpyArray a = ReadNpy(path);
  if (a.shape.size() != 2 || a.shape[1] != 17) {
    throw std::runtime_error(path + ": expected an N x 17 array of LLFF poses and bounds");
  }
  if (a.shape[0] != image_names.size()) {
    throw std::runtime_error(path + ": holds " + std::to_string(a.shape[0]) + " poses but " +
                             std::to_string(image_names.size()) + " photos were given");
  }
  std::map<std::string, ReferenceCamera> cameras;
  for (size_t i = 0; i < a.shape[0]; ++i) {
    const double* row = &a.data[i * 17];
    // 3x5 row-major: M(r, c) = row[5 r + c].
    Eigen::Matrix3d llff;
    Eigen::Vector3d centre;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) llff(r, c) = row[5 * r + c];
      centre[r] = row[5 * r + 3];
    }
    // LLFF camera axes (down, right, back) -> COLMAP's (right, down, forward).
    Eigen::Matrix3d c2w;
    c2w.col(0) = llff.col(1);
    c2w.col(1) = llff.col(0);
    c2w.col(2) = -llff.col(2);
    if (!IsRotation(c2w, 1e-4)) {
      throw std::runtime_error(path + ": row " + std::to_string(i) + " is not a rotation");
    }
    ReferenceCamera cam;
    cam.pose = PoseFromCameraToWorld(c2w, centre);
    cam.height = static_cast<int>(std::lround(row[4]));
    cam.width = static_cast<int>(std::lround(row[9]));
    cam.focal_px = row[14];
    cameras[image_names[i]] = cam;
  }
  return cameras;
}

ReferenceCamera ReadStrechaCamera(const std::string& path) {
  std::istringstream in(io::ReadFile(path));
  // K (9), distortion (3), R (9), C (3), width and height (2).
  double v[26];
  for (int i = 0; i < 26; ++i) {
    if (!(in >> v[i]) || !std::isfinite(v[i])) {
      throw std::runtime_error(path + ": expected 26 numbers (K, distortion, R, C, width height)");
    }
  }
  ReferenceCamera cam;
  cam.focal_px = v[0];
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R(r, c) = v[12 + 3 * r + c];
  }
  if (!IsRotation(R, 1e-4)) throw std::runtime_error(path + ": R is not a rotation");
  cam.pose = PoseFromCameraToWorld(R, Eigen::Vector3d(v[21], v[22], v[23]));
  cam.width = static_cast<int>(std::lround(v[24]));
  cam.height = static_cast<int>(std::lround(v[25]));
  return cam;
}

std::map<std::string, ReferenceCamera> ReadStrechaCameras(const std::string& dir) {
  DIR* d = ::opendir(dir.c_str());
  if (d == nullptr) throw std::runtime_error(dir + ": cannot open folder: " + std::strerror(errno));
  std::vector<std::string> files;
  while (dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    if (name.size() > 7 && name.compare(name.size() - 7, 7, ".camera") == 0) files.push_back(name);
  }
  ::closedir(d);
  std::map<std::string, ReferenceCamera> cameras;
  for (const auto& f : files) cameras[f.substr(0, f.size() - 7)] = ReadStrechaCamera(dir + "/" + f);
  if (cameras.empty()) throw std::runtime_error(dir + ": no *.camera files");
  return cameras;
}

PoseComparison ComparePoses(const std::map<std::string, geometry::Pose>& estimated,
                            const std::map<std::string, geometry::Pose>& reference) {
  std::vector<std::string> names;
  std::vector<Eigen::Vector3d> src, dst;
  for (const auto& [name, pose] : estimated) {
    const auto it = reference.find(name);
    if (it == reference.end()) continue;
    names.push_back(name);
    src.push_back(pose.Center());
    dst.push_back(it->second.Center());
  }
  PoseComparison c;
  c.num_common = static_cast<int>(names.size());
  if (names.size() < 3) {
    throw std::runtime_error("pose comparison: only " + std::to_string(names.size()) +
                             " photos in common; need 3");
  }
  // Rotation: the chordal L2 mean of the per-photo rotations that map the
  // estimate's world into the reference's (R = R_ref^T R_est for each photo).
  // The camera centres of a casual capture lie on a small cap (Sec. 4.1: a
  // 0.3 m arm), which fixes this rotation far less well than the photos'
  // orientations do; a rotation taken from the centres (Umeyama) would put
  // its own error into every photo's rotation and centre error.
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (const auto& name : names) {
    sum += reference.at(name).R().transpose() * estimated.at(name).R();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
  fix(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  c.alignment.R = svd.matrixU() * fix * svd.matrixV().transpose();
  // Scale and translation: least squares on the centres given R.
  Eigen::Vector3d mean_src = Eigen::Vector3d::Zero(), mean_dst = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < names.size(); ++i) {
    mean_src += src[i] / names.size();
    mean_dst += dst[i] / names.size();
  }
  double num = 0, den = 0;
  for (size_t i = 0; i < names.size(); ++i) {
    num += (c.alignment.R * (src[i] - mean_src)).dot(dst[i] - mean_dst);
    den += (src[i] - mean_src).squaredNorm();
  }
  if (!(den > 1e-24) || !(num > 0)) {
    throw std::runtime_error("pose comparison: camera centres are degenerate (all equal)");
  }
  c.alignment.scale = num / den;
  c.alignment.t = mean_dst - c.alignment.scale * (c.alignment.R * mean_src);
  for (size_t i = 0; i < names.size(); ++i) {
    const geometry::Pose aligned = c.alignment.ApplyToPose(estimated.at(names[i]));
    const geometry::Pose& ref = reference.at(names[i]);
    const double rot = geometry::RotationAngleDeg(aligned.rotation, ref.rotation);
    const double ctr = (aligned.Center() - ref.Center()).norm();
    c.max_rotation_error_deg = std::max(c.max_rotation_error_deg, rot);
    c.mean_rotation_error_deg += rot / names.size();
    c.max_centre_error = std::max(c.max_centre_error, ctr);
    c.mean_centre_error += ctr / names.size();
    for (size_t j = 0; j < i; ++j) c.reference_spread = std::max(c.reference_spread, (dst[i] - dst[j]).norm());
  }
  return c;
}

}  // namespace casual3d::sfm

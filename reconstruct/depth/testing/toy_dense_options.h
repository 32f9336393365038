#pragma once

// The dense options the toy-scene tests run the stage with.

#include <string>

#include "reconstruct/depth/dense_stage.h"

namespace casual3d::depth::testing {

// Half working scale, 2 threads, evaluated against the depth maps in
// `ground_truth_dir` (the toy workspace's gt/).
inline DenseOptions ToyDenseOptions(const std::string& ground_truth_dir) {
  DenseOptions o;
  o.working_scale = 0.5;
  o.num_threads = 2;
  o.ground_truth_dir = ground_truth_dir;
  return o;
}

}  // namespace casual3d::depth::testing

#pragma once

// The dense stage's MRF (Sec. 4.3.1-4.3.2, Eq. 1-4) over one photo's
// working-resolution grid, assembled for TRW-S (mrf_trws.h).

#include <vector>

#include "format/image.h"
#include "reconstruct/depth/dense_stage.h"
#include "reconstruct/depth/median_prune.h"
#include "reconstruct/depth/mrf_trws.h"

namespace casual3d::depth {

// Turns `mrf->unary`, which holds the photo's matching costs E_photo
// (width * height * num_labels, as CostVolume::cost), into the data term,
// and sets the smoothness weights:
//   unary:  w_photo E_photo(k), plus far_bias * (1 - w_photo) * (1 - k / (L - 1))
//           where no flat-region prior applies (far_bias 0 by default), plus lambda_flat * (1 - w_photo)
//           * min(|k - prior|, T_flat) / T_flat where one does (flat_regions.h;
//           NaN = none), plus lambda_near on labels nearer than `envelope`'s
//           (Eq. 4) when `envelope` is not empty;
//   edges:  lambda_smooth / T * max(color_floor, w_color) between 4-neighbours,
//           w_color = exp(-|c_p - c_q|^2 / (2 sigma_color^2)) of `color`.
// `mrf`'s width, height and num_labels must be set, `photo_weight` and
// `color` of that size; `grid` maps the envelope's depths to labels.
void AssembleDenseMrf(const ImageF& photo_weight, const ImageF& color, const std::vector<float>& flat_prior,
                      const ImageF& envelope, const LabelGrid& grid, const MrfTermOptions& options,
                      GridMrf* mrf);

}  // namespace casual3d::depth

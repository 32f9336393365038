#pragma once

// Virtual rephotography (paper Sec. 6.3): the 3D photo as one of the capture's
// photos saw it, with the photo's own camera model including lens distortion,
// so that the rendering can be compared pixel by pixel with the photo as shot.
//
// Method: the mesh is rendered with mesh_renderer.h into an undistorted
// pinhole canvas with the camera's focal lengths, enlarged to contain every
// undistorted ray of the photo; each photo pixel then looks up its undistorted
// ray (Camera::Unproject) in the canvas. Depth and coverage come from the
// nearest canvas pixel (depth, the camera-frame z, does not change along a
// ray); colour is the bilinear interpolation of the covered canvas pixels
// around the ray, so that uncovered pixels never bleed into covered ones.

#include "format/equirect.h"
#include "format/image.h"
#include "format/mesh.h"
#include "reconstruct/geometry/camera.h"
#include "reconstruct/geometry/pose.h"
#include "reconstruct/render/mesh_renderer.h"

namespace casual3d::render {

// Renders `mesh` (panorama frame) as `camera` at `pose` (world to camera)
// sees it, `frame` relating the world to the panorama frame. The result has
// the camera's size. Cameras without distortion are rendered directly (the
// same bytes as RenderMesh(ViewFromPhoto(...))). Throws std::invalid_argument
// for an invalid camera or the errors of RenderMesh.
RenderResult RenderPhotoView(const Mesh& mesh, ImageView<const uint8_t> atlas,
                             const PanoramaFrame& frame, const geometry::Camera& camera,
                             const geometry::Pose& pose, const RenderOptions& options = {});

}  // namespace casual3d::render

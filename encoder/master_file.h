#pragma once

// The master file: a lossless two-layer panorama in OpenEXR, the hand-off from
// reconstruction to encoding and the archival form of a 3D photo.
//
// Layout (one scanline part, ZIP compression, data window (0,0)-(w-1,h-1)):
//   Channels, for L in {front, back} (layer 0 and 1 of TwoLayerPanorama):
//     L.present  UINT   1 if the node exists, else 0
//     L.R L.G L.B UINT  sRGB colour, 0..255 (not linear light)
//     L.Z        FLOAT  depth in metres (distance from the frame centre)
//     L.N.X L.N.Y L.N.Z FLOAT  unit normal in the panorama frame, or 0,0,0
//     L.label    UINT   NodeLabel (0 = F, 1 = B)
//     L.links    UINT   the 4 packed Links (bits 2d..2d+1 for direction d)
//   Header attributes:
//     casual3d.format   string "casual3d-master"
//     casual3d.version  string "1.0" (major.minor; unknown majors are refused)
//     casual3d.centre   v3d    PanoramaFrame::centre
//     casual3d.rotation m33d   PanoramaFrame::rotation (row-major)
//     casual3d.view     string OPTIONAL: the view hints (format/view_hints.h)
//                              as the JSON object of the manifest's "view"
// Float values are stored as 32-bit floats, so a write followed by a read gives
// back exactly the same panorama (bit for bit).

#include <string>

#include "format/status.h"
#include "format/two_layer.h"

namespace casual3d::encoder {

// Largest master file accepted by ReadMasterFile (pixels per side).
constexpr int kMaxMasterWidth = 32768;
constexpr int kMaxMasterHeight = 16384;

// Writes `pano` to `path` atomically: the data goes to a temporary file next to
// `path` that is renamed over it only when complete. Fails (without touching
// `path`) if `pano.Validate()` fails or the file cannot be written.
Status WriteMasterFile(const TwoLayerPanorama& pano, const std::string& path);

// Reads a master file written by WriteMasterFile. Returns kNotFound if the file
// does not exist, kInvalidData for a file that is not an OpenEXR master file or
// whose content is malformed (missing channels, wrong types, a panorama that
// does not Validate()), kUnsupportedVersion for an unknown major version and
// kLimitExceeded beyond kMaxMasterWidth x kMaxMasterHeight. Never throws.
StatusOr<TwoLayerPanorama> ReadMasterFile(const std::string& path);

}  // namespace casual3d::encoder

#pragma once

// How a 3D photo should be looked at: the direction and field of view that
// frame its captured content, the angular extent of that content, and the
// viewing volume (the ball around the centre in which the eye may move) that
// the capture supports. Stored in the manifest's optional "view" member
// (spec/package.md Sec. 3.1, version 1.1) and in the master file's header.
// Standard library only.

#include <string>
#include <string_view>

#include "format/json.h"
#include "format/status.h"

namespace casual3d {

struct ViewHints {
  // Initial view direction: longitude and latitude in degrees (the panorama
  // frame of projection.md: yaw 0 looks along -Z, +90 along +X; pitch +90
  // looks up). yaw in [-180, 180], pitch in [-90, 90].
  double yaw_deg = 0;
  double pitch_deg = 0;
  // Initial vertical field of view (degrees) that frames the content, in
  // [10, 120].
  double fov_deg = 75;
  // Angular extent of the captured content. The longitudes form the interval
  // [content_yaw_min_deg, content_yaw_max_deg] taken modulo 360, with
  // -360 <= min <= max <= 360 and max - min <= 360 (360: the whole circle).
  // Latitudes: -90 <= min <= max <= 90.
  double content_yaw_min_deg = -180;
  double content_yaw_max_deg = 180;
  double content_pitch_min_deg = -90;
  double content_pitch_max_deg = 90;
  // Radius of the viewing volume, a ball around the frame centre, in the
  // unit of the panorama's depths: the eye should stay inside it. > 0, finite.
  double volume_radius = 0.1;
  // Whether the depths are in metres (known scale: synthetic captures, a
  // model with known scale); otherwise they are in the capture's own
  // arbitrary unit and only ratios are meaningful.
  bool metric = false;

  // Checks the ranges above; the message names the field.
  Status Validate() const;
  bool operator==(const ViewHints& other) const;
  bool operator!=(const ViewHints& other) const { return !(*this == other); }
};

// The JSON object of the manifest's "view" member (spec/package.md Sec. 3.1)
// and back. FromJson checks members, types and ranges; messages name the
// member ("content_yaw_deg: expected 2 numbers").
json::Value ViewHintsToJson(const ViewHints& hints);
Status ViewHintsFromJson(const json::Value& object, ViewHints* hints);
// The same object as compact JSON text (the master file's casual3d.view).
std::string SerializeViewHints(const ViewHints& hints);
StatusOr<ViewHints> ParseViewHints(std::string_view text);

}  // namespace casual3d

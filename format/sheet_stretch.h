#pragma once

// Sheets seen from off the centre (spec/mesh.md Sec. 8, informative). A
// triangle of the mesh that links nodes across a depth step (the sealing of
// spec/stage-panorama.md closes quads where three surfaces meet that way) is
// about one panorama pixel wide seen from the centre, and a streak of
// interpolated colour many pixels long seen from elsewhere. A viewer that
// draws the backdrop (format/backdrop.h) may leave out the fragments of a
// triangle that looks more than a limit times larger from the eye than from
// the centre, so that what lies behind it (the back layer, or the backdrop)
// shows instead of the streak. Seen from the centre nothing is left out.
//
// The stretch of a triangle is the largest singular value of the map from
// directions seen from the centre, u = p / |p|, to directions seen from the
// eye, e = (p - eye) / |p - eye|, across the triangle: with the edge matrices
// Ju = [u1 - u0, u2 - u0] and Je = [e1 - e0, e2 - e0] and the Gram matrices
// Gu = Ju^T Ju, Ge = Je^T Je, it is 1 / sqrt(l), l the smaller root of
// det(Gu - l Ge) = 0. The WebGL viewer evaluates the same quantity per
// fragment with screen-space derivatives of u and e in place of the edges.

namespace casual3d {

// The viewer's default limit: a sheet across a depth ratio of 0.75 or less
// seen from the boundary of the viewing volume stretches 5 to 30 times; a
// surface seen from there, about 1 to 1.2 times.
constexpr double kDefaultSheetStretch = 4.0;

// The stretch of triangle (a, b, c) (positions in the panorama frame, whose
// origin is the centre) seen from `eye`. 0 when the triangle is edge-on or
// degenerate seen from the eye (nothing of it is drawn); +infinity when it is
// degenerate seen from the centre but not from the eye.
double SheetStretch(const float a[3], const float b[3], const float c[3], const double eye[3]);

// The smaller root l of det(Gu - l Ge) = 0 for 2x2 symmetric Gram matrices
// given as (g11, g12, g22), computed without cancellation; -1 when Ge is
// singular. Shared with the viewer's shader, which uses the same formula.
double SmallerGeneralisedEigenvalue(const double gu[3], const double ge[3]);

}  // namespace casual3d

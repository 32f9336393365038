#pragma once

// The named MUST-refuse rules of spec/package.md (Sec. 9, "Reader
// conformance") that a package reader enforces, one per invalid conformance
// vector (spec/vectors/invalid/<name>), and a set of them that readers take.
// Every check is on by default. Switching one off exists for conformance
// tests: an invalid vector that breaks exactly one rule is refused with every
// check on and accepted with only its own check off. Reading stays in bounds
// with any check off, but a reader with `path-escape` off may read outside the
// package folder: never switch checks off for untrusted packages.
// Header-only, standard library only.

#include <cstdint>
#include <string_view>

namespace casual3d {

enum class ReaderCheck : int {
  kUnknownMajor = 0,          // manifest "version" with a major other than 1 or 2
  kNestingTooDeep,            // manifest.json nested deeper than 16
  kNearEqualsFar,             // depth_encoding near_m == far_m
  kPathEscape,                // a path that is not a safe package-relative path
  kSizeMismatch,              // a file's size differs from its "bytes"
  kChecksumMismatch,          // a file's SHA-256 differs from its "sha256"
  kLossyDataTile,             // a depth, normal or graph image that is not lossless WebP
  kWrongTileSize,             // a tile image of another size than Sec. 4 gives
  kReservedFlagBits,          // graph flag bits 4..7 set
  kDepthCodeAboveMax,         // a present node's depth code above 2^bits - 1
  kNormalCodeInvalid,         // a present node's octahedral code with one 0 or above the maximum
  kPresentNodeWithoutDepth,   // a present node with depth code 0
  kLinkNotMutual,             // a link to an absent node or without its reverse link
  kContainerUnknownMajor,     // .c3d header major version other than 1
  kManifestNotFirst,          // .c3d first entry other than manifest.json
  kDuplicateEntry,            // .c3d entries sharing a path
  kEntryOutsideFile,          // .c3d entry whose data range leaves the file
  kLeftUpLinkBits,            // 2.x: a present node's graph byte with left or up link bits
};
constexpr int kNumReaderChecks = 18;

// The check's name: the name of its invalid vector ("checksum-mismatch").
constexpr std::string_view ReaderCheckName(ReaderCheck check) {
  constexpr std::string_view kNames[kNumReaderChecks] = {
      "unknown-major",       "nesting-too-deep",          "near-equals-far",
      "path-escape",         "size-mismatch",             "checksum-mismatch",
      "lossy-data-tile",     "wrong-tile-size",           "reserved-flag-bits",
      "depth-code-above-max", "normal-code-invalid",      "present-node-without-depth",
      "link-not-mutual",     "container-unknown-major",   "manifest-not-first",
      "duplicate-entry",     "entry-outside-file",        "left-up-link-bits"};
  const int i = static_cast<int>(check);
  return i >= 0 && i < kNumReaderChecks ? kNames[i] : std::string_view("unknown");
}

// The check named `name`; false if there is none.
constexpr bool ReaderCheckFromName(std::string_view name, ReaderCheck* check) {
  for (int i = 0; i < kNumReaderChecks; ++i) {
    if (ReaderCheckName(static_cast<ReaderCheck>(i)) == name) {
      *check = static_cast<ReaderCheck>(i);
      return true;
    }
  }
  return false;
}

// A set of checks; all on by default.
class ReaderChecks {
 public:
  constexpr ReaderChecks() = default;
  // Every check except `check`.
  static constexpr ReaderChecks AllBut(ReaderCheck check) {
    ReaderChecks c;
    c.Disable(check);
    return c;
  }
  constexpr bool on(ReaderCheck check) const {
    return (off_ >> static_cast<int>(check) & 1u) == 0;
  }
  constexpr void Disable(ReaderCheck check) { off_ |= 1u << static_cast<int>(check); }

 private:
  uint32_t off_ = 0;  // Bit i set: check i is off.
};

}  // namespace casual3d

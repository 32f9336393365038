#pragma once

// SHA-256 (FIPS 180-4), the checksum of every file of a package. Standard
// library only.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace casual3d {

using Sha256Digest = std::array<uint8_t, 32>;

// Digest of `size` bytes at `data` (data may be null when size is 0).
Sha256Digest Sha256(const uint8_t* data, size_t size);

// Lower-case hexadecimal form (64 characters).
std::string Sha256Hex(const uint8_t* data, size_t size);

}  // namespace casual3d

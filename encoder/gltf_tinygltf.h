#pragma once

// Includes tinygltf (Debian's libtinygltf-dev header) for casual3d's glTF code.
//
// The tinygltf implementation is compiled into casual3d_encoder (gltf_export.cc
// defines TINYGLTF_IMPLEMENTATION, as Debian's README.Debian describes) under a
// private namespace, casual3d_tinygltf, instead of linking libtinygltf.so:
// Debian's libdraco (shared and static) also defines tinygltf:: symbols, those
// of the older tinygltf bundled in Draco's own glTF I/O, built without image
// support. With both libraries in one program the linker or the dynamic loader
// picks one definition per symbol, and calls ended up in Draco's copy. Renaming
// the namespace keeps the two apart whatever the link order.
//
// Images are encoded and decoded by casual3d itself (libpng, libjpeg), so
// tinygltf's stb_image options are off: a reader must install an image loader
// (TinyGLTF::SetImageLoader) to load a file with images.
//
// TINYGLTF_ENABLE_DRACO lets the reader decode KHR_draco_mesh_compression
// primitives (with Debian's libdraco), so that exported files can be read back.
//
// Every file that uses tinygltf in casual3d includes this header, never
// <tiny_gltf.h> directly, so that all translation units agree on the macros.

#define tinygltf casual3d_tinygltf
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#define TINYGLTF_ENABLE_DRACO
#include <tiny_gltf.h>

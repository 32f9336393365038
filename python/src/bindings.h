#pragma once

// The parts of the extension module casual3d._casual3d, one per job; each
// adds its functions to the module (python/src/module.cc calls them). The
// pure-Python layer (python/casual3d/__init__.py) wraps them in the public API.

#include <pybind11/pybind11.h>

namespace casual3d::python {

// _Package (open, manifest, read a level), _read_master, _validate.
void RegisterReading(pybind11::module_& m);
// _build_mesh, _color_atlas.
void RegisterMeshes(pybind11::module_& m);
// _write_package, _write_master, _export_glb.
void RegisterWriting(pybind11::module_& m);

}  // namespace casual3d::python

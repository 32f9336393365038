// The extension module casual3d._casual3d (pybind11): the C++ format and
// encoder libraries behind `import casual3d`.

#include <pybind11/pybind11.h>

#include "format/version.h"
#include "python/src/bindings.h"
#include "python/src/errors.h"

PYBIND11_MODULE(_casual3d, m) {
  m.doc() = "casual3d's format and encoder libraries; use the casual3d package, not this module.";
  m.attr("__version__") = casual3d::kVersion;  // project(VERSION), format/version.h.
  casual3d::python::RegisterErrors(m);
  casual3d::python::RegisterReading(m);
  casual3d::python::RegisterMeshes(m);
  casual3d::python::RegisterWriting(m);
}

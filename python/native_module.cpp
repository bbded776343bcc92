// evio._native: the compiled half of the Python package `evio` (python/evio/):
// a sequence folder's streams as NumPy arrays, read by the project's own
// readers (sequence_arrays.h). evio.Error is raised for every evio error.
#include <pybind11/pybind11.h>

#include "evio/core/error.h"
#include "evio/core/io/media_module.h"
#include "sequence_arrays.h"

namespace py = pybind11;

PYBIND11_MODULE(_native, m) {
  m.doc() = "evio's sequence readers (use the package `evio`)";
  static py::exception<evio::Error> error(m, "Error", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const evio::Error& e) {
      error(e.what());
    }
  });
  evio::python::addSequenceReaders(m);
  m.def("set_media_module", &evio::io::media::setModulePath, py::arg("path"),
        "where the media module (libevio_media.so) is, for frames in formats other than PNG");
}

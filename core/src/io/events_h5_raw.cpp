#include "evio/core/io/events_h5_raw.h"

#include <cstdio>

#include "events_h5_hdf5.h"
#include "evio/core/io/atomic_file.h"

namespace evio::io::h5raw {

namespace {

hid_t fileType(Type type) {
  switch (type) {
    case Type::kUint8: return H5T_STD_U8LE;
    case Type::kInt8: return H5T_STD_I8LE;
    case Type::kUint16: return H5T_STD_U16LE;
    case Type::kInt16: return H5T_STD_I16LE;
    case Type::kUint32: return H5T_STD_U32LE;
    case Type::kInt32: return H5T_STD_I32LE;
    case Type::kUint64: return H5T_STD_U64LE;
    case Type::kInt64: return H5T_STD_I64LE;
    case Type::kFloat64: return H5T_IEEE_F64LE;
  }
  return H5T_STD_I64LE;
}

h5::Handle openForRead(const std::string& path) {
  return h5::file(h5::check(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), path, "",
                            "cannot open HDF5 file"));
}

void writeAll(const std::string& path, const std::string& tmp,
              const std::vector<Dataset>& datasets) {
  h5::Handle file = h5::file(h5::check(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT,
                                                 H5P_DEFAULT),
                                       path, "", "cannot create file"));
  h5::Handle lcpl = h5::plist(h5::check(H5Pcreate(H5P_LINK_CREATE), path, "", "plist"));
  h5::checkStatus(H5Pset_create_intermediate_group(lcpl.get(), 1), path, "", "plist");
  for (const Dataset& d : datasets) {
    if (d.scalar && d.values.size() != 1)
      throw Error::inField(path, 0, d.name, "a scalar needs exactly one value");
    h5::Handle space = d.scalar ? h5::dataspace(h5::check(H5Screate(H5S_SCALAR), path, d.name,
                                                          "dataspace"))
                                : h5::simpleSpace(d.values.size(), path, d.name);
    h5::Handle ds = h5::dataset(h5::check(H5Dcreate2(file.get(), d.name.c_str(), fileType(d.type),
                                                     space.get(), lcpl.get(), H5P_DEFAULT,
                                                     H5P_DEFAULT),
                                          path, d.name, "cannot create dataset"));
    if (!d.values.empty())
      h5::checkStatus(H5Dwrite(ds.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                               d.values.data()),
                      path, d.name, "write failed");
  }
  if (!file.reset()) h5::fail(path, "", "cannot finish writing the file");
}

}  // namespace

void writeDatasets(const std::string& path, const std::vector<Dataset>& datasets) {
  h5::QuietErrors quiet;
  const std::string tmp = temporaryPathFor(path);
  try {
    writeAll(path, tmp, datasets);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  renameFile(tmp, path);
}

std::vector<std::int64_t> readDataset(const std::string& path, const std::string& name) {
  h5::QuietErrors quiet;
  h5::Handle file = openForRead(path);
  h5::Handle ds = h5::dataset(
      h5::check(H5Dopen2(file.get(), name.c_str(), H5P_DEFAULT), path, name, "cannot open"));
  h5::Handle space = h5::dataspace(h5::check(H5Dget_space(ds.get()), path, name, "dataspace"));
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  if (n < 0) h5::fail(path, name, "cannot get size");
  std::vector<std::int64_t> values(static_cast<std::size_t>(n));
  if (n > 0)
    h5::checkStatus(
        H5Dread(ds.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), path,
        name, "read failed");
  return values;
}

std::string datasetType(const std::string& path, const std::string& name) {
  h5::QuietErrors quiet;
  h5::Handle file = openForRead(path);
  h5::Handle ds = h5::dataset(
      h5::check(H5Dopen2(file.get(), name.c_str(), H5P_DEFAULT), path, name, "cannot open"));
  h5::Handle type = h5::datatype(h5::check(H5Dget_type(ds.get()), path, name, "no type"));
  return h5::typeName(type.get());
}

}  // namespace evio::io::h5raw

#include "events_h5_hdf5.h"

namespace evio::io::h5 {

QuietErrors::QuietErrors() {
  saved_ = H5Eget_auto2(H5E_DEFAULT, &func_, &data_) >= 0;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

QuietErrors::~QuietErrors() {
  if (saved_) H5Eset_auto2(H5E_DEFAULT, func_, data_);
}

namespace {
herr_t keepInnermost(unsigned /*n*/, const H5E_error2_t* err, void* client) {
  // Walking downward, the last entry visited is the innermost (the origin).
  if (err && err->desc && err->desc[0] != '\0') *static_cast<std::string*>(client) = err->desc;
  return 0;
}
}  // namespace

std::string takeHdf5Message() {
  std::string msg;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, keepInnermost, &msg);
  H5Eclear2(H5E_DEFAULT);
  return msg;
}

void fail(const std::string& file, std::string_view field, std::string_view what) {
  std::string message(what);
  const std::string detail = takeHdf5Message();
  if (!detail.empty()) {
    message.append(" (HDF5: ");
    message.append(detail);
    message.push_back(')');
  }
  if (field.empty()) throw Error::inFile(file, 0, message);
  throw Error::inField(file, 0, field, message);
}

hid_t check(hid_t id, const std::string& file, std::string_view field, std::string_view what) {
  if (id < 0) fail(file, field, what);
  return id;
}

herr_t checkStatus(herr_t status, const std::string& file, std::string_view field,
                   std::string_view what) {
  if (status < 0) fail(file, field, what);
  return status;
}

Handle simpleSpace(std::uint64_t n, const std::string& file, std::string_view field) {
  const hsize_t dims[1] = {static_cast<hsize_t>(n)};
  return dataspace(check(H5Screate_simple(1, dims, nullptr), file, field, "cannot create dataspace"));
}

void selectRange(hid_t space, std::uint64_t begin, std::uint64_t count, const std::string& file,
                 std::string_view field) {
  const hsize_t start[1] = {static_cast<hsize_t>(begin)};
  const hsize_t n[1] = {static_cast<hsize_t>(count)};
  checkStatus(H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, n, nullptr), file, field,
              "cannot select range");
}

std::string typeName(hid_t type) {
  const H5T_class_t cls = H5Tget_class(type);
  const std::size_t bits = H5Tget_size(type) * 8;
  switch (cls) {
    case H5T_INTEGER:
      return std::string(H5Tget_sign(type) == H5T_SGN_NONE ? "uint" : "int") + std::to_string(bits);
    case H5T_FLOAT:
      return "float" + std::to_string(bits);
    case H5T_STRING:
      return "string";
    case H5T_ENUM:
      return "enum";
    case H5T_COMPOUND:
      return "compound";
    default:
      return "non-numeric type";
  }
}

}  // namespace evio::io::h5

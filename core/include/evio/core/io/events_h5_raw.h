#pragma once
/// @file events_h5_raw.h
/// Low-level access to numeric HDF5 datasets, for tools and tests that must
/// look beneath EventH5Writer/EventH5Reader: inspect the stored type of
/// /events/t, read /ms_to_idx verbatim, or build files that violate the DSEC
/// layout on purpose (a missing dataset, mismatched lengths, decreasing time)
/// to exercise the reader's validation. Callers never see HDF5 headers.

#include <cstdint>
#include <string>
#include <vector>

namespace evio::io::h5raw {

/// Stored element type of a dataset written by writeDatasets().
enum class Type { kUint8, kInt8, kUint16, kInt16, kUint32, kInt32, kUint64, kInt64, kFloat64 };

/// One dataset: `name` is an absolute path ("/events/t"); groups are created
/// as needed. Values are converted to `type` by HDF5 (out-of-range values are
/// clipped). `scalar` writes a rank-0 dataset from values[0].
struct Dataset {
  std::string name;
  Type type = Type::kInt64;
  std::vector<std::int64_t> values;
  bool scalar = false;
};

/// Writes the datasets (contiguous, uncompressed) to `path` atomically.
/// Throws evio::Error naming the file and dataset on failure.
void writeDatasets(const std::string& path, const std::vector<Dataset>& datasets);

/// Reads a numeric dataset whole as int64 (HDF5 converts). Throws on failure.
std::vector<std::int64_t> readDataset(const std::string& path, const std::string& name);

/// The stored type of a dataset: "uint32", "int64", "float64", ...
std::string datasetType(const std::string& path, const std::string& name);

}  // namespace evio::io::h5raw

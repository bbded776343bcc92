#pragma once
/// @file estimate_files.h
/// The estimate folder: what an estimator (`evio estimate … -o <folder>`)
/// writes and `evio evaluate` reads. Only trajectory.txt is required.
///
///   trajectory.txt             TUM (core/io/tum.h): T_W_C of the event camera,
///                              the frame of groundtruth.txt
///   trajectory_covariance.txt  optional, the same poses in the covariance TUM
///                              variant (ov_eval layout): orientation block in
///                              the "local" convention R_true = R̂·Exp(δθ)
///                              (experiments/nees.h), position block in W, m²
///   timing.txt                 optional (core/io/timing_txt.h): for RTF
///   status.yaml                optional (core/io/status_yaml.h): ok | diverged | failed
///
/// A ground-truth argument is a TUM file, or a sequence folder holding
/// groundtruth.txt.

#include <string>

namespace evio::experiments {

struct EstimateFiles {
  std::string trajectory;  ///< always set
  std::string covariance;  ///< empty when absent
  std::string timing;      ///< empty when absent
  std::string status;      ///< empty when absent
};

/// Resolves `estimate` (a folder, or a trajectory file whose folder holds the
/// optional files) to the files that exist. Throws evio::Error when the
/// trajectory does not exist.
EstimateFiles findEstimateFiles(const std::string& estimate);

/// `groundtruth` itself, or <folder>/groundtruth.txt for a folder; throws
/// when it does not exist.
std::string findGroundtruthFile(const std::string& groundtruth);

}  // namespace evio::experiments

#pragma once
/// @file stage.h
/// One stage of the estimator's chain (docs/architecture.md#the-estimator-stages):
/// one input type, one output type. The pipeline hands each input to
/// process(), which appends what it produces (zero, one or more outputs, in
/// time order) for the next stage. A stage knows nothing of its neighbours,
/// so a new frontend, or a stage run on its own thread behind a queue, plugs
/// in without touching the others.

#include <vector>

namespace evio::estimator {

template <class In, class Out>
class Stage {
 public:
  using Input = In;
  using Output = Out;
  virtual ~Stage() = default;
  /// Consumes `in` (it may be moved from or swapped with a spare) and appends its outputs to `out`.
  virtual void process(In& in, std::vector<Out>& out) = 0;
};

}  // namespace evio::estimator

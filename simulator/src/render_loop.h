#pragma once
// The render scheduling loop of simulateSequence (sequence_simulator.h,
// "Render scheduling"): renders the event camera at adaptive whole-frame
// steps or, with sampling.schedule "tiles", re-renders only the tiles due
// (tile_schedule.h); whole renders at frame sub-samples, frame stamps and the
// end; feeds the event camera, the frame camera and the writer in time
// order. The event stage of a step (event camera, events to the writer)
// runs while the next step is scheduled and rendered (render_loop.cpp,
// EventStage).

#include <opencv2/core/mat.hpp>

#include "evio/core/pose.h"
#include "evio/scenes/scene.h"
#include "evio/simulator/scenario.h"
#include "evio/simulator/sequence_simulator.h"
#include "evio/simulator/sequence_writer.h"

namespace evio::simulator {

struct RenderLoopResult {
  cv::Mat first_depth;  ///< event-camera depth at the sequence start (track points)
  Pose first_T_W_E;     ///< its pose
};

/// Runs the loop over [scenario.start_ns, scenario.end_ns]; adds counts and
/// stage times to *stats.
RenderLoopResult runRenderLoop(const Scenario& scenario, const scenes::Scene& scene, AsyncSequenceWriter& writer,
                               const ProgressCallback& progress, SimulationStats* stats);

}  // namespace evio::simulator

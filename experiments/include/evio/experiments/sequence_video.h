#pragma once
/// @file sequence_video.h
/// A sequence folder as a video (`evio video`): for each video frame at
/// t_k = t_first + k · speed / fps, two panels side by side:
///   left   the latest APS frame with t ≤ t_k (grey when there is none yet);
///   right  the events of (t_k − window, t_k] on mid-grey: brighter (ON)
///          events white, darker (OFF) events black, so the panel looks
///          like the brightness change over the window;
/// on both, tracks (ground-truth `truth/tracks.txt` or a tracks file of
/// `evio track`) as coloured dots with their last `track_tail_s` of motion,
/// and on top the time and the event rate over the window.
/// Streams everything: events in chunks (memory: the events of one
/// window), frames one at a time, tracks one sample at a time (memory: one
/// entry per live track; a tracks file whose lines are out of time order
/// only draws a sample one video frame late).

#include <functional>
#include <string>

namespace evio::experiments {

struct VideoOptions {
  double fps = 30.0;             ///< video frames per second of video time
  double speed = 1.0;            ///< sequence seconds per video second (< 1: slow motion)
  double window_s = 0.01;        ///< event accumulation window, s
  double track_tail_s = 0.2;     ///< how much of a track's past is drawn, s
  int scale = 2;                 ///< pixels of video per sensor pixel
  std::string tracks;            ///< tracks file ("": <sequence>/truth/tracks.txt if present; "none": no tracks)
  void validate() const;
};

struct VideoSummary {
  std::size_t frames = 0;        ///< video frames written
  std::size_t events = 0;        ///< events drawn
  int width = 0, height = 0;     ///< video size, px
  std::string codec;             ///< FourCC used ("avc1" H.264, else "mp4v" MPEG-4 part 2)
  std::string tracks_file;       ///< tracks drawn ("" none)
};

/// Writes `output` (.mp4 or .avi) from the sequence `folder`. `progress`
/// gets the share done (0..1). Throws evio::Error naming the file on bad
/// input or when no encoder can write `output`.
VideoSummary writeSequenceVideo(const std::string& folder, const std::string& output, const VideoOptions& options,
                                const std::function<void(double)>& progress = {});

}  // namespace evio::experiments

#include "evio/estimator/frontend/haste_tracker.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "evio/core/error.h"
#include "evio/estimator/frontend/feature_detection.h"
#include "evio/estimator/frontend/log_image.h"

namespace evio::estimator {

struct HasteTracker::Slot {
  enum class State : std::uint8_t { kFree, kSeeded, kStarted };
  explicit Slot(const HasteOptions& options) : feature(options) {}
  State state = State::kFree;
  FeatureId id = 0;
  TimeNs t_seed_ns = 0;
  HasteFeature feature;
  PixelRect rect;                 // where the grid has this slot's bit
  Vec2 last_uv = Vec2::Zero();    // last point sent
  TimeNs last_t_ns = 0;
  bool pending = false;           // the state moved since the last point sent
};

/// One part of the feature partition: slots s with s mod parts == its index.
struct HasteTracker::Part {
  Part(int width, int height, int num_slots) : grid(width, height, num_slots) { points.reserve(256); }
  FeatureGrid grid;                // the bits of this part's slots only
  std::vector<ChunkPoint> points;  // of the current chunk, in (event, slot) order
  HasteCounters counters;          // feature_updates and jumps of the current chunk
};

HasteTracker::HasteTracker(const HasteOptions& options, const Camera& camera, int threads)
    : options_(options),
      width_(camera.width()),
      height_(camera.height()),
      half_(0.5 * (options.patch_size_px - 1)),
      border_px_(options.lost_border_px) {
  options_.validate();
  require(threads >= 1 && threads <= 256, "HasteTracker: threads must be in [1, 256]");
  const int num_parts = std::min(threads, options_.max_features);
  for (int k = 0; k < num_parts; ++k) {
    parts_.push_back(std::make_unique<Part>(width_, height_, options_.max_features));
    part_points_.push_back(&parts_.back()->points);
  }
  if (num_parts > 1) pool_ = std::make_unique<WorkerPool>(num_parts);
  slots_.reserve(static_cast<std::size_t>(options_.max_features));
  for (int i = 0; i < options_.max_features; ++i) slots_.emplace_back(options_);
  const std::size_t n = static_cast<std::size_t>(options_.history_events);
  history_x_.assign(n, 0);
  history_y_.assign(n, 0);
  history_t_.assign(n, 0);
  out_.reserve(1024);
}

HasteTracker::~HasteTracker() = default;

PixelRect HasteTracker::rangeRect(double x, double y) const {
  // Integer pixels e with |e − c| < h on both axes (a superset of the disc).
  return PixelRect{static_cast<int>(std::floor(x - half_)) + 1, static_cast<int>(std::floor(y - half_)) + 1,
                   static_cast<int>(std::ceil(x + half_)) - 1, static_cast<int>(std::ceil(y + half_)) - 1};
}

int HasteTracker::freeSlot() const {
  for (std::size_t i = 0; i < slots_.size(); ++i)
    if (slots_[i].state == Slot::State::kFree) return static_cast<int>(i);
  return -1;
}

std::size_t HasteTracker::numAlive() const {
  return static_cast<std::size_t>(
      std::count_if(slots_.begin(), slots_.end(), [](const Slot& s) { return s.state != Slot::State::kFree; }));
}

void HasteTracker::drainTrackPoints(TrackPoints& out) {
  out.insert(out.end(), out_.begin(), out_.end());
  out_.clear();
}

std::optional<HasteState> HasteTracker::feature(FeatureId id) const {
  for (const Slot& s : slots_)
    if (s.state == Slot::State::kStarted && s.id == id) return s.feature.state();
  return std::nullopt;
}

void HasteTracker::moveRect(int index) {
  Slot& s = slots_[static_cast<std::size_t>(index)];
  const PixelRect rect = rangeRect(s.feature.state().x, s.feature.state().y);
  if (rect.x0 == s.rect.x0 && rect.y0 == s.rect.y0 && rect.x1 == s.rect.x1 && rect.y1 == s.rect.y1) return;
  partOf(index).grid.move(index, s.rect, rect);
  s.rect = rect;
}

void HasteTracker::free(int index) {
  Slot& s = slots_[static_cast<std::size_t>(index)];
  partOf(index).grid.move(index, s.rect, PixelRect{});
  s.rect = PixelRect{};
  s.state = Slot::State::kFree;
}

void HasteTracker::seed(int index, const Vec2& uv, TimeNs t_ns, double theta) {
  Slot& s = slots_[static_cast<std::size_t>(index)];
  s.state = Slot::State::kSeeded;
  s.id = next_id_++;
  s.t_seed_ns = t_ns;
  s.feature.reset(HasteState{t_ns, uv.x(), uv.y(), theta});
  moveRect(index);
  if (!options_.centered_initialization || history_count_ == 0) return;
  // The newest (N − 1)/2 in-range events of the history, fed oldest first.
  const int wanted = (s.feature.windowSize() - 1) / 2;
  const std::size_t cap = history_x_.size();
  std::size_t k = 0;
  int found = 0;
  for (; k < history_count_ && found < wanted; ++k) {
    const std::size_t i = (history_head_ + cap - 1 - k) % cap;
    if (s.feature.inRange(history_x_[i], history_y_[i])) ++found;
  }
  for (std::size_t j = k; j-- > 0;) {
    const std::size_t i = (history_head_ + cap - 1 - j) % cap;
    s.feature.addEvent(history_t_[i], history_x_[i], history_y_[i]);  // fills; never starts (found < N)
  }
}

FeatureId HasteTracker::addFeature(const Vec2& uv, TimeNs t_ns, double theta_rad) {
  const int index = freeSlot();
  require(index >= 0, "HasteTracker::addFeature: all max_features slots are in use");
  seed(index, uv, t_ns, theta_rad);
  return slots_[static_cast<std::size_t>(index)].id;
}

void HasteTracker::recordHistory(TimeNs t_ns, int x, int y) {
  const std::size_t cap = history_x_.size();
  if (cap == 0) return;
  history_x_[history_head_] = x;
  history_y_[history_head_] = y;
  history_t_[history_head_] = t_ns;
  history_head_ = (history_head_ + 1) % cap;
  history_count_ = std::min(history_count_ + 1, cap);
}

void HasteTracker::onUpdate(Part& part, int index, HasteFeature::Update update, std::size_t event_index) {
  Slot& s = slots_[static_cast<std::size_t>(index)];
  if (update == HasteFeature::Update::kOutOfRange || update == HasteFeature::Update::kFilling) return;
  const HasteState& st = s.feature.state();
  const Vec2 uv(st.x, st.y);
  if (update == HasteFeature::Update::kStarted) {
    s.state = Slot::State::kStarted;
    s.pending = false;
    s.last_uv = uv;
    s.last_t_ns = st.t_ns;
    part.points.push_back(ChunkPoint{event_index, index, TrackPoint{s.id, st.t_ns, uv, 1.0, TrackStatus::kNew}});
    return;
  }
  if (update == HasteFeature::Update::kJump) {
    ++part.counters.jumps;
    const bool inside = st.x >= border_px_ && st.y >= border_px_ && st.x <= width_ - 1 - border_px_ &&
                        st.y <= height_ - 1 - border_px_;
    if (!inside) {
      part.points.push_back(
          ChunkPoint{event_index, index, TrackPoint{s.id, s.last_t_ns, s.last_uv, 1.0, TrackStatus::kLost}});
      free(index);
      return;
    }
    moveRect(index);
    s.pending = true;
  }
  if (!s.pending) return;
  if (options_.one_point_per_window && st.t_ns - s.last_t_ns < s.feature.windowSpanNs()) return;
  s.pending = false;
  s.last_uv = uv;
  s.last_t_ns = st.t_ns;
  part.points.push_back(ChunkPoint{event_index, index, TrackPoint{s.id, st.t_ns, uv, 1.0, TrackStatus::kTracked}});
}

void HasteTracker::addEvents(const EventArray& events, std::size_t begin, std::size_t end) {
  trackInParts(events, begin, end);
  mergeChunkPoints(part_points_, out_);
  afterTracking(events, begin, end);
}

void HasteTracker::addEventChunks(const EventArray& events, const std::vector<std::size_t>& chunk_ends,
                                  TrackPoints& out, std::vector<std::size_t>& point_ends) {
  drainTrackPoints(out);
  const std::size_t end = chunk_ends.empty() ? 0 : chunk_ends.back();
  trackInParts(events, 0, end);
  mergeChunkPoints(part_points_, chunk_ends, out, point_ends);
  afterTracking(events, 0, end);
}

void HasteTracker::trackInParts(const EventArray& events, std::size_t begin, std::size_t end) {
  const auto& x = events.x();
  const auto& y = events.y();
  for (std::size_t i = begin; i < end; ++i) {
    const int ex = x[i];
    const int ey = y[i];
    if (ex < 0 || ey < 0 || ex >= width_ || ey >= height_) throw Error("HasteTracker: event outside the sensor");
  }
  if (pool_) {
    auto task = [&](int k) { trackChunk(*parts_[static_cast<std::size_t>(k)], events, begin, end); };
    pool_->run(task);
  } else {
    trackChunk(*parts_.front(), events, begin, end);
  }
  for (auto& part : parts_) {
    counters_.feature_updates += part->counters.feature_updates;
    counters_.jumps += part->counters.jumps;
    part->counters = HasteCounters{};
  }
}

void HasteTracker::afterTracking(const EventArray& events, std::size_t begin, std::size_t end) {
  // The history is read only when a feature is seeded (addFrame): recorded
  // after the chunk (or a segment of chunks) was tracked, it is the same as
  // recorded event by event.
  const auto& t = events.t();
  const auto& x = events.x();
  const auto& y = events.y();
  for (std::size_t i = begin; i < end; ++i) recordHistory(t[i], x[i], y[i]);
  counters_.events += end - begin;
}

void HasteTracker::trackChunk(Part& part, const EventArray& events, std::size_t begin, std::size_t end) {
  const auto& t = events.t();
  const auto& x = events.x();
  const auto& y = events.y();
  const int words = part.grid.words();
  for (std::size_t i = begin; i < end; ++i) {
    const int ex = x[i];
    const int ey = y[i];
    const std::uint64_t* cell = part.grid.at(ex, ey);
    for (int w = 0; w < words; ++w) {
      std::uint64_t bits = cell[w];  // a copy: a jump may rewrite the grid
      while (bits != 0) {
        const int index = 64 * w + std::countr_zero(bits);
        bits &= bits - 1;
        Slot& s = slots_[static_cast<std::size_t>(index)];
        const HasteFeature::Update u = s.feature.addEvent(t[i], ex, ey);
        if (u == HasteFeature::Update::kRegular || u == HasteFeature::Update::kJump) ++part.counters.feature_updates;
        onUpdate(part, index, u, i);
      }
    }
  }
}

void HasteTracker::addFrame(TimeNs t_ns, const cv::Mat& image) {
  require(image.cols == width_ && image.rows == height_, "HasteTracker: frame size differs from the camera's");
  // Seeds that never filled their window (texture-less spots) are dropped.
  const auto timeout = static_cast<TimeNs>(std::llround(options_.seed_timeout_s * 1e9));
  for (std::size_t i = 0; i < slots_.size(); ++i)
    if (slots_[i].state == Slot::State::kSeeded && t_ns - slots_[i].t_seed_ns > timeout) free(static_cast<int>(i));

  const std::size_t alive = numAlive();
  if (alive >= static_cast<std::size_t>(options_.min_features)) return;
  std::vector<Vec2> existing;
  for (const Slot& s : slots_)
    if (s.state != Slot::State::kFree) existing.emplace_back(s.feature.state().x, s.feature.state().y);
  HarrisSettings hs;
  hs.max_corners = options_.max_features - static_cast<int>(alive);
  hs.quality_level = options_.harris_quality_level;
  hs.min_distance_px = options_.min_distance_px;
  hs.block_size = options_.harris_block_size;
  hs.k = options_.harris_k;
  hs.border_px = static_cast<int>(std::ceil(std::max(border_px_, half_))) + 1;
  for (const Vec2& corner : detectHarris(toEightBit(image), existing, hs)) {
    const int index = freeSlot();
    if (index < 0) break;
    seed(index, corner, t_ns, 0.0);
  }
}

}  // namespace evio::estimator

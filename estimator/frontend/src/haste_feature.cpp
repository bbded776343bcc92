#include "evio/estimator/frontend/haste_feature.h"

#include <cmath>

namespace evio::estimator {

HasteFeature::HasteFeature(const HasteOptions& options)
    : variant_(parseHasteVariant(options.variant)),
      p_(options.patch_size_px),
      half_(0.5 * (options.patch_size_px - 1)),
      n_(options.windowSize()),
      margin_(options.margin),
      template_update_(options.template_update) {
  options.validate();
  const double d = options.step_px;
  const double r = options.step_deg * M_PI / 180.0;
  // (dx, dy, dθ): null, ±x, ±y, the four diagonals, ±θ.
  const double table[kHypotheses][3] = {{0, 0, 0},  {+d, 0, 0},  {-d, 0, 0},  {0, +d, 0},  {0, -d, 0}, {+d, +d, 0},
                                        {-d, +d, 0}, {-d, -d, 0}, {+d, -d, 0}, {0, 0, +r}, {0, 0, -r}};
  for (int h = 0; h < kHypotheses; ++h)
    offsets_[static_cast<std::size_t>(h)] = HasteState{0, table[h][0], table[h][1], table[h][2]};
  const std::size_t n = static_cast<std::size_t>(n_);
  const std::size_t pp = static_cast<std::size_t>(p_) * static_cast<std::size_t>(p_);
  ex_.assign(n, 0.0);
  ey_.assign(n, 0.0);
  et_.assign(n, 0);
  uniform_ = 1.0 / n_;
  // Gaussian weights over the window position, σ = N/6, centred on the middle event, Σg = 1.
  gauss_.assign(n, 0.0);
  const double sigma = n_ / 6.0;
  const double mid = 0.5 * (n_ - 1);
  double sum = 0.0;
  for (int k = 0; k < n_; ++k) {
    const double z = (k - mid) / sigma;
    gauss_[static_cast<std::size_t>(k)] = std::exp(-0.5 * z * z);
    sum += gauss_[static_cast<std::size_t>(k)];
  }
  for (double& g : gauss_) g /= sum;
  template_.assign(pp, 0.0);
  reference_.assign(pp, 0.0);
  if (variant_ == HasteVariant::kCorrelation) samples_.assign(kHypotheses * n, 0.0);
  if (variant_ == HasteVariant::kDifference || variant_ == HasteVariant::kDifferenceStar)
    differences_.assign(kHypotheses * pp, 0.0);
}

void HasteFeature::reset(const HasteState& seed) {
  started_ = false;
  count_ = 0;
  head_ = 0;
  centreHypotheses(seed);
  scores_.fill(0.0);
}

bool HasteFeature::inRange(double ex, double ey) const {
  const double dx = ex - state().x;
  const double dy = ey - state().y;
  return dx * dx + dy * dy < half_ * half_;
}

HasteFeature::Update HasteFeature::addEvent(TimeNs t_ns, double ex, double ey) {
  if (!inRange(ex, ey)) return Update::kOutOfRange;
  if (!started_) {
    const std::size_t slot = static_cast<std::size_t>(count_);
    ex_[slot] = ex;
    ey_[slot] = ey;
    et_[slot] = t_ns;
    if (++count_ < n_) return Update::kFilling;
    head_ = 0;
    start();
    return Update::kStarted;
  }
  // Replace the oldest event; the ring's head moves to the next oldest.
  const std::size_t s = static_cast<std::size_t>(head_);
  const double old_x = ex_[s];
  const double old_y = ey_[s];
  ex_[s] = ex;
  ey_[s] = ey;
  et_[s] = t_ns;
  head_ = (head_ + 1) % n_;
  const TimeNs t_mid = et_[static_cast<std::size_t>(ringIndex((n_ - 1) / 2))];
  for (HasteState& hyp : hypotheses_) hyp.t_ns = t_mid;
  updateScores(ex, ey, old_x, old_y);
  const int best = bestHypothesis();
  Update result = Update::kRegular;
  if (best != kNull) {
    jumpTo(best);
    result = Update::kJump;
  }
  updateTemplate();
  return result;
}

void HasteFeature::start() {
  started_ = true;
  std::fill(template_.begin(), template_.end(), 0.0);
  const bool gaussian = variant_ == HasteVariant::kCorrelation;
  for (int k = 0; k < n_; ++k) {
    const std::size_t i = static_cast<std::size_t>(ringIndex(k));
    double ux = 0.0, uy = 0.0;
    patchPoint(kNull, ex_[i], ey_[i], &ux, &uy);
    splat(template_, ux, uy, gaussian ? gauss_[static_cast<std::size_t>(k)] : uniform_);
  }
  HasteState s = state();
  s.t_ns = et_[static_cast<std::size_t>(ringIndex((n_ - 1) / 2))];
  centreHypotheses(s);
  refreshReference();
  initialiseScores();
}

void HasteFeature::jumpTo(int h) {
  const HasteState s = hypotheses_[static_cast<std::size_t>(h)];
  centreHypotheses(s);
  refreshReference();
  initialiseScores();
}

void HasteFeature::centreHypotheses(const HasteState& centre) {
  for (int h = 0; h < kHypotheses; ++h) {
    const HasteState& o = offsets_[static_cast<std::size_t>(h)];
    HasteState& hyp = hypotheses_[static_cast<std::size_t>(h)];
    hyp = HasteState{centre.t_ns, centre.x + o.x, centre.y + o.y, centre.theta + o.theta};
    rot_[static_cast<std::size_t>(h)] = Rot{std::cos(hyp.theta), std::sin(hyp.theta)};
  }
}

void HasteFeature::refreshReference() {
  double sum = 0.0;
  for (double v : template_) sum += v;
  const double inv = sum > 0.0 ? 1.0 / sum : 0.0;
  for (std::size_t i = 0; i < template_.size(); ++i) reference_[i] = template_[i] * inv;
}

void HasteFeature::patchPoint(int h, double ex, double ey, double* ux, double* uy) const {
  const HasteState& hyp = hypotheses_[static_cast<std::size_t>(h)];
  const Rot& r = rot_[static_cast<std::size_t>(h)];
  const double dx = ex - hyp.x;
  const double dy = ey - hyp.y;
  *ux = r.c * dx + r.s * dy + half_;
  *uy = -r.s * dx + r.c * dy + half_;
}

double HasteFeature::sample(const std::vector<double>& patch, double ux, double uy) const {
  if (!(ux >= 0.0 && uy >= 0.0 && ux < p_ - 1 && uy < p_ - 1)) return 0.0;
  const int ix = static_cast<int>(ux);
  const int iy = static_cast<int>(uy);
  const double fx = ux - ix;
  const double fy = uy - iy;
  const double* row = patch.data() + static_cast<std::ptrdiff_t>(iy) * p_ + ix;
  return (1.0 - fy) * ((1.0 - fx) * row[0] + fx * row[1]) + fy * ((1.0 - fx) * row[p_] + fx * row[p_ + 1]);
}

void HasteFeature::splat(std::vector<double>& patch, double ux, double uy, double weight) const {
  if (!(ux >= 0.0 && uy >= 0.0 && ux < p_ - 1 && uy < p_ - 1)) return;
  const int ix = static_cast<int>(ux);
  const int iy = static_cast<int>(uy);
  const double fx = ux - ix;
  const double fy = uy - iy;
  double* row = patch.data() + static_cast<std::ptrdiff_t>(iy) * p_ + ix;
  row[0] += weight * (1.0 - fx) * (1.0 - fy);
  row[1] += weight * fx * (1.0 - fy);
  row[p_] += weight * (1.0 - fx) * fy;
  row[p_ + 1] += weight * fx * fy;
}

void HasteFeature::initialiseScores() {
  for (int h = 0; h < kHypotheses; ++h) {
    const std::size_t hh = static_cast<std::size_t>(h);
    switch (variant_) {
      case HasteVariant::kCorrelation: {
        double* row = samples_.data() + hh * static_cast<std::size_t>(n_);
        for (int i = 0; i < n_; ++i) {
          double ux = 0.0, uy = 0.0;
          patchPoint(h, ex_[static_cast<std::size_t>(i)], ey_[static_cast<std::size_t>(i)], &ux, &uy);
          row[i] = sample(reference_, ux, uy);
        }
        scores_[hh] = scoreFromScratch(h);
        break;
      }
      case HasteVariant::kCorrelationStar:
        scores_[hh] = scoreFromScratch(h);
        break;
      case HasteVariant::kDifference:
      case HasteVariant::kDifferenceStar:
        scores_[hh] = modelDifferenceScore(h);
        break;
    }
  }
}

double HasteFeature::modelDifferenceScore(int h) {
  // D_h = R̂ − M_h/N, built in the hypothesis' cache; S_h = −ΣD².
  const std::size_t pp = reference_.size();
  double* d = differences_.data() + static_cast<std::size_t>(h) * pp;
  std::copy(reference_.begin(), reference_.end(), d);
  for (int i = 0; i < n_; ++i) {
    double ux = 0.0, uy = 0.0;
    patchPoint(h, ex_[static_cast<std::size_t>(i)], ey_[static_cast<std::size_t>(i)], &ux, &uy);
    if (!(ux >= 0.0 && uy >= 0.0 && ux < p_ - 1 && uy < p_ - 1)) continue;
    const int ix = static_cast<int>(ux);
    const int iy = static_cast<int>(uy);
    const double fx = ux - ix;
    const double fy = uy - iy;
    double* row = d + static_cast<std::ptrdiff_t>(iy) * p_ + ix;
    row[0] -= uniform_ * (1.0 - fx) * (1.0 - fy);
    row[1] -= uniform_ * fx * (1.0 - fy);
    row[p_] -= uniform_ * (1.0 - fx) * fy;
    row[p_ + 1] -= uniform_ * fx * fy;
  }
  double s = 0.0;
  for (std::size_t k = 0; k < pp; ++k) s -= d[k] * d[k];
  return s;
}

void HasteFeature::updateDifference(int h, double ux, double uy, double increment) {
  if (!(ux >= 0.0 && uy >= 0.0 && ux < p_ - 1 && uy < p_ - 1)) return;
  const int ix = static_cast<int>(ux);
  const int iy = static_cast<int>(uy);
  const double fx = ux - ix;
  const double fy = uy - iy;
  double* row = differences_.data() + static_cast<std::size_t>(h) * reference_.size() +
                static_cast<std::ptrdiff_t>(iy) * p_ + ix;
  double* cells[4] = {row, row + 1, row + p_, row + p_ + 1};
  const double w[4] = {(1.0 - fx) * (1.0 - fy), fx * (1.0 - fy), (1.0 - fx) * fy, fx * fy};
  double& score = scores_[static_cast<std::size_t>(h)];
  for (int k = 0; k < 4; ++k) {
    score += *cells[k] * *cells[k];  // remove the cell's old contribution to −ΣD²
    *cells[k] += increment * w[k];
    score -= *cells[k] * *cells[k];  // and add its new one
  }
}

void HasteFeature::updateScores(double new_x, double new_y, double old_x, double old_y) {
  const int newest_slot = (head_ + n_ - 1) % n_;
  for (int h = 0; h < kHypotheses; ++h) {
    const std::size_t hh = static_cast<std::size_t>(h);
    double un_x = 0.0, un_y = 0.0, uo_x = 0.0, uo_y = 0.0;
    patchPoint(h, new_x, new_y, &un_x, &un_y);
    switch (variant_) {
      case HasteVariant::kCorrelation: {
        double* row = samples_.data() + hh * static_cast<std::size_t>(n_);
        row[newest_slot] = sample(reference_, un_x, un_y);
        double s = 0.0;
        for (int k = 0; k < n_; ++k) s += gauss_[static_cast<std::size_t>(k)] * row[ringIndex(k)];
        scores_[hh] = s;
        break;
      }
      case HasteVariant::kCorrelationStar:
        patchPoint(h, old_x, old_y, &uo_x, &uo_y);
        scores_[hh] += uniform_ * (sample(reference_, un_x, un_y) - sample(reference_, uo_x, uo_y));
        break;
      case HasteVariant::kDifference:
        scores_[hh] = modelDifferenceScore(h);
        break;
      case HasteVariant::kDifferenceStar:
        patchPoint(h, old_x, old_y, &uo_x, &uo_y);
        updateDifference(h, un_x, un_y, -uniform_);  // the new event enters M_h
        updateDifference(h, uo_x, uo_y, +uniform_);  // the dropped one leaves it
        break;
    }
  }
}

int HasteFeature::bestHypothesis() const {
  int best = kNull;
  int worst = kNull;
  for (int h = 1; h < kHypotheses; ++h) {
    if (scores_[static_cast<std::size_t>(h)] > scores_[static_cast<std::size_t>(best)]) best = h;
    if (scores_[static_cast<std::size_t>(h)] < scores_[static_cast<std::size_t>(worst)]) worst = h;
  }
  const double s_best = scores_[static_cast<std::size_t>(best)];
  const double s_null = scores_[kNull];
  const double s_worst = scores_[static_cast<std::size_t>(worst)];
  if (best != kNull && s_best > s_null && (s_best - s_null) > margin_ * (s_best - s_worst)) return best;
  return kNull;
}

void HasteFeature::updateTemplate() {
  const int mid = (n_ - 1) / 2;
  const std::size_t i = static_cast<std::size_t>(ringIndex(mid));
  const double w = variant_ == HasteVariant::kCorrelation ? gauss_[static_cast<std::size_t>(mid)] : uniform_;
  double ux = 0.0, uy = 0.0;
  patchPoint(kNull, ex_[i], ey_[i], &ux, &uy);
  splat(template_, ux, uy, template_update_ * w);
}

double HasteFeature::scoreFromScratch(int h) const {
  switch (variant_) {
    case HasteVariant::kCorrelation:
    case HasteVariant::kCorrelationStar: {
      const bool gaussian = variant_ == HasteVariant::kCorrelation;
      double s = 0.0;
      for (int k = 0; k < n_; ++k) {
        const std::size_t i = static_cast<std::size_t>(ringIndex(k));
        double ux = 0.0, uy = 0.0;
        patchPoint(h, ex_[i], ey_[i], &ux, &uy);
        s += (gaussian ? gauss_[static_cast<std::size_t>(k)] : uniform_) * sample(reference_, ux, uy);
      }
      return s;
    }
    case HasteVariant::kDifference:
    case HasteVariant::kDifferenceStar: {
      std::vector<double> model(reference_.size(), 0.0);  // tests only: allocation is fine here
      for (int i = 0; i < n_; ++i) {
        double ux = 0.0, uy = 0.0;
        patchPoint(h, ex_[static_cast<std::size_t>(i)], ey_[static_cast<std::size_t>(i)], &ux, &uy);
        splat(model, ux, uy, 1.0);
      }
      double s = 0.0;
      for (std::size_t k = 0; k < model.size(); ++k) {
        const double d = reference_[k] - model[k] * uniform_;
        s -= d * d;
      }
      return s;
    }
  }
  return 0.0;
}

}  // namespace evio::estimator

// `evio stats` on the real DAVIS240C slices in tests/data/ecd/ (Mueggler et
// al., IJRR 2017, CC BY-NC-SA 3.0), each figure against an independent Python
// computation (Debian's /usr/bin/python3 with numpy and matplotlib), run in the
// slice's folder. Counts and quantiles must be equal; other numbers agree to
// 1e-9 relative (both sides sum exact integers; only the last bits of a
// division or of a variance may differ).
#include <gtest/gtest.h>

#include "evio/experiments/sequence_stats.h"

namespace evio::experiments {
namespace {

const std::string kEcd = std::string(EVIO_SOURCE_DIR) + "/tests/data/ecd/";

void expectRelative(double actual, double expected) { EXPECT_NEAR(actual, expected, 1e-9 * std::abs(expected)); }

// Events. Every Python line starts from
//   E=[(round(float(t)*1e9),int(x),int(y),int(p)) for t,x,y,p in map(str.split,open('events.txt'))]
//   q=lambda v,p: sorted(v)[-(-p*len(v)//100)-1]
TEST(SequenceStatsEcd, ShapesRotationEventsMatchAnIndependentComputation) {
  const SequenceStats s = computeSequenceStats(kEcd + "shapes_rotation_events");
  const EventStreamStats& e = s.events;
  EXPECT_EQ(s.width, 240);  // events reach x = 239, y = 179
  EXPECT_EQ(s.height, 180);
  EXPECT_EQ(e.count, 50879u);                       // len(E)
  expectRelative(e.durationS(), 0.899990001);       // (E[-1][0]-E[0][0])/1e9
  expectRelative(e.onFraction(), 0.4292930285579512);  // sum(e[3] for e in E)/len(E)
  // import collections; W=collections.Counter((t-E[0][0])//10**7 for t,*_ in E)
  // w=[W[k]/0.01 for k in range((E[-1][0]-E[0][0])//10**7)]; q(w,50),q(w,90),max(w)
  expectRelative(e.window_rate_hz.p50, 25500.0);
  expectRelative(e.window_rate_hz.p90, 167100.0);
  expectRelative(e.window_rate_hz.max, 219200.0);
  // L={};I=[]; for t,x,y,p in E: (I.append(t-L[x,y,p]) if (x,y,p) in L else 0); L[x,y,p]=t
  // len(I), min(I)/1e9, [q([i//1000 for i in I],p)/1e6 for p in (1,5,50)], sum(i<10**6 for i in I)/len(I)
  EXPECT_EQ(e.interval_count, 38767u);
  expectRelative(e.interval_s.min, 0.001659);
  expectRelative(e.interval_s.p1, 0.002423);
  expectRelative(e.interval_s.p5, 0.002993);
  expectRelative(e.interval_s.p50, 0.008167);
  EXPECT_EQ(e.interval_under_1ms_fraction, 0.0);
  // B=[];L={};c={}
  // for t,x,y,p in E: k=(x,y,p); (k in L and t-L[k]>5*10**6) and (B.append(c[k]), c.update({k:0})); c[k]=c.get(k,0)+1; L[k]=t
  // B+=list(c.values()); len(B), q(B,50), q(B,90), max(B)
  EXPECT_EQ(e.burst_count, 40662u);
  EXPECT_EQ(e.events_per_burst.p50, 1.0);
  EXPECT_EQ(e.events_per_burst.p90, 2.0);
  EXPECT_EQ(e.events_per_burst.max, 7.0);
  // Brute force: P[x,y] = sorted times of each pixel; an event is isolated when the
  // 3x3 block holds exactly one event (itself) in [t-10**7, t+10**7] (bisect).
  EXPECT_EQ(e.isolated_count, 1751u);
  expectRelative(e.isolated_rate_hz_per_pixel, 0.04503650858606306);  // 1751/(240*180*0.899990001)
  // C=collections.Counter((x,y) for t,x,y,p in E); pc=[C[x,y] for x in range(240) for y in range(180)]
  // [q(pc,p) for p in (50,90,99)], max(pc)
  EXPECT_EQ(e.pixel_count.p50, 0.0);
  EXPECT_EQ(e.pixel_count.p90, 5.0);
  EXPECT_EQ(e.pixel_count.p99, 13.0);
  EXPECT_EQ(e.pixel_count.max, 32.0);
}

// Frames. Every Python line starts from
//   import numpy as np, matplotlib.image as mi; S=[l.split() for l in open('images.txt')]
//   F=[np.rint(mi.imread(f)*255).astype(np.int64) for t,f in S]; A=np.stack(F)
TEST(SequenceStatsEcd, Boxes6dofFramesMatchAnIndependentComputation) {
  const FrameStreamStats f = computeSequenceStats(kEcd + "boxes_6dof_frames").frames;
  EXPECT_EQ(f.count, 60u);  // len(F)
  EXPECT_EQ(f.width, 240);
  EXPECT_EQ(f.height, 180);
  expectRelative(f.rateHz(), 21.70828064837869);  // (len(S)-1)/(float(S[-1][0])-float(S[0][0]))
  EXPECT_FALSE(f.exposure_s.has_value());          // 5 ms on the recording, but no file says so
  expectRelative(f.brightness_mean_dn, 45.08579089506173);  // A.mean()
  expectRelative(f.fraction_at_0, 0.12000038580246913);     // (A==0).mean()
  EXPECT_EQ(f.fraction_at_255, 0.0);                         // (A==255).mean()
  // mx=[f.max() for f in F]; q(mx,50); np.mean([(f==f.max()).mean() for f in F])
  EXPECT_EQ(f.max_dn.p50, 125.0);
  expectRelative(f.fraction_at_max, 3.4722222222222215e-05);
  // wl=[max(v for v in range(256) if 200*(f==v).sum()>=f.size) for f in F]; q(wl,50)
  // np.mean([(f>=w-10).mean() for f,w in zip(F,wl)])
  EXPECT_EQ(f.white_level_dn.p50, 118.0);
  expectRelative(f.fraction_near_white, 0.11586033950617283);
  // np.mean([(f[1:-1,:-2]+f[1:-1,2:]+f[:-2,1:-1]+f[2:,1:-1]-4*f[1:-1,1:-1]).var() for f in F])
  expectRelative(f.laplacian_variance_dn2, 422.6019617624298);
}

}  // namespace
}  // namespace evio::experiments

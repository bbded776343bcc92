#include "evio/experiments/campaign_report.h"

#include <gtest/gtest.h>

#include <cmath>

#include "evio/experiments/campaign_results.h"
#include "evio/experiments/nees.h"

namespace evio::experiments {
namespace {

TEST(CampaignReport, SpreadIsMedianAndQuartiles) {
  const Spread s = spreadOf({5.0, 1.0, 3.0, 2.0, 4.0, NAN});
  EXPECT_EQ(s.count, 5u);
  EXPECT_DOUBLE_EQ(s.median, 3.0);
  EXPECT_DOUBLE_EQ(s.q1, 2.0);
  EXPECT_DOUBLE_EQ(s.q3, 4.0);
  const Spread even = spreadOf({1.0, 2.0, 3.0, 4.0});
  EXPECT_DOUBLE_EQ(even.median, 2.5);
  EXPECT_DOUBLE_EQ(even.q1, 1.75);
  EXPECT_TRUE(std::isnan(spreadOf({}).median));
}

TEST(CampaignReport, AggregatesRunsPerScenarioMethodAndSweep) {
  const std::string summary =
      "job_id,scenario,method,sweep,seed,done,status,cause,alignment.describe,paper.mpe_percent,"
      "paper.mye_deg_per_m,ate.position_m.rmse,ate.rotation_deg.rmse,completion.share,nees.available,"
      "nees.mean_pose,rtf.available,rtf.median,rtf.max\n"
      "a1,hover,eklt,,1,1,ok,,posyaw on all poses (10),1.0,0.1,0.01,0.5,1,true,5.0,true,0.5,0.9\n"
      "a2,hover,eklt,,2,1,ok,,posyaw on all poses (10),3.0,0.3,0.03,0.7,1,true,7.0,true,0.7,1.4\n"
      "a3,hover,eklt,,3,1,diverged,\"bound, exceeded\",posyaw on all poses (10),50,5,2,9,0.4,true,600,true,0.6,0.8\n"
      "a4,hover,eklt,,4,1,failed,estimate: exit code 3,,,,,,,,,,,\n"
      "a5,hover,eklt,,5,0,,,,,,,,,,,,,\n"
      "b1,hover,klt,x=1,1,1,ok,,posyaw on all poses (10),2.0,0.2,0.02,0.6,1,false,,false,,\n";
  const CampaignReport r = aggregateSummary(parseCsv(summary));
  EXPECT_EQ(r.jobs, 6u);
  EXPECT_EQ(r.finished, 5u);
  ASSERT_EQ(r.groups.size(), 2u);
  const ReportGroup& g = r.groups[0];
  EXPECT_EQ(g.method, "eklt");
  EXPECT_EQ(g.runs, 5u);
  EXPECT_EQ(g.ok, 2u);
  EXPECT_EQ(g.diverged, 1u);
  EXPECT_EQ(g.failed, 1u);
  EXPECT_EQ(g.pending, 1u);
  EXPECT_DOUBLE_EQ(g.successRate(), 0.4);
  EXPECT_EQ(g.alignment, "posyaw on all poses");
  EXPECT_DOUBLE_EQ(g.mpe_percent.median, 2.0);  // successful runs only: 1 and 3
  EXPECT_EQ(g.completion.count, 3u);            // every finished, not failed run
  EXPECT_EQ(g.nees_runs, 3u);
  EXPECT_DOUBLE_EQ(g.anees, (5.0 + 7.0 + 600.0) / 3.0);
  const auto [lo, hi] = neesBounds(6, 3);
  EXPECT_DOUBLE_EQ(g.anees_lower, lo);
  EXPECT_DOUBLE_EQ(g.anees_upper, hi);
  EXPECT_DOUBLE_EQ(g.rtf_median.median, 0.6);
  EXPECT_DOUBLE_EQ(g.rtf_max, 1.4);
  EXPECT_EQ(r.groups[1].sweep, "x=1");
  EXPECT_EQ(r.groups[1].nees_runs, 0u);

  const std::string md = reportMarkdown(r, "Test", {"box_mpe.png"}, {"skipped nees.png: no covariance"});
  EXPECT_NE(md.find("## hover"), std::string::npos);
  EXPECT_NE(md.find("| eklt | – | 5 (1 pending) | 40 % | 1 | 1 | 2.00 [1.50, 2.50] |"), std::string::npos) << md;
  EXPECT_NE(md.find("✗"), std::string::npos);  // ANEES 204 is outside its bounds
  EXPECT_NE(md.find("![box_mpe.png](box_mpe.png)"), std::string::npos);
  EXPECT_NE(md.find("- skipped nees.png: no covariance"), std::string::npos);
  const auto csv = parseCsv(reportCsv(r));
  ASSERT_EQ(csv.size(), 3u);
  EXPECT_EQ(csv[1].size(), csv[0].size());
  EXPECT_EQ(csv[2][2], "x=1");
}

TEST(CampaignReport, SelfDiagnosisIsCountedAgainstTheTruthsVerdict) {
  const std::string summary =
      "job_id,scenario,method,sweep,seed,done,status,estimator_status,divergence.truth_diverged\n"
      "a1,rot,eklt,,1,1,ok,ok,false\n"             // quiet
      "a2,rot,eklt,,2,1,ok,degraded,false\n"       // false alarm
      "a3,rot,eklt,,3,1,diverged,degraded,true\n"  // caught
      "a4,rot,eklt,,4,1,diverged,ok,true\n"        // missed
      "a5,rot,eklt,,5,1,diverged,diverged,true\n"  // caught (the estimator's own divergence)
      "a6,rot,eklt,,6,1,failed,failed,false\n"     // failed: not judged
      "a7,rot,eklt,,7,1,ok,ok,\n";                 // no truth verdict (older results): not judged
  const CampaignReport r = aggregateSummary(parseCsv(summary));
  ASSERT_EQ(r.groups.size(), 1u);
  const SelfDiagnosisAgreement& a = r.groups[0].self_diagnosis;
  EXPECT_EQ(a.caught, 2u);
  EXPECT_EQ(a.missed, 1u);
  EXPECT_EQ(a.false_alarms, 1u);
  EXPECT_EQ(a.quiet, 1u);
  EXPECT_EQ(a.judged(), 5u);
  EXPECT_NE(selfDiagnosisMarkdown(r).find("| rot | eklt | – | 5 | 2 | 1 | 1 | 1 |"), std::string::npos)
      << selfDiagnosisMarkdown(r);
  EXPECT_NE(reportMarkdown(r, "T", {}, {}).find("## Self-diagnosis"), std::string::npos);
}

TEST(CampaignReport, ComparisonTableHasMediansPerScenarioAndTheirMean) {
  const std::string summary =
      "job_id,scenario,method,sweep,seed,done,status,cause,alignment.describe,paper.mpe_percent,"
      "paper.mye_deg_per_m,ate.position_m.rmse,ate.rotation_deg.rmse,completion.share,nees.available,"
      "nees.mean_pose,rtf.available,rtf.median,rtf.max\n"
      "a1,poster,eklt,,1,1,ok,,,1.0,0.10,,,1,false,,false,,\n"
      "a2,poster,eklt,,2,1,ok,,,3.0,0.30,,,1,false,,false,,\n"
      "b1,poster,klt,,1,1,ok,,,2.0,0.20,,,1,false,,false,,\n"
      "b2,poster,klt,,2,1,diverged,,,90,9,,,1,false,,false,,\n"
      "c1,shapes,eklt,,1,1,ok,,,4.0,0.40,,,1,false,,false,,\n"
      "d1,shapes,klt,,1,1,failed,x,,,,,,,,,,,\n"
      "e1,rotation,eklt,,1,1,ok,,,,,0.25,3.5,1,false,,false,,\n"
      "f1,rotation,klt,,1,1,ok,,,,,0.05,0.5,1,false,,false,,\n";
  const CampaignReport r = aggregateSummary(parseCsv(summary));
  const std::string md = comparisonMarkdown(r);
  EXPECT_NE(md.find("| scenario | eklt | klt |"), std::string::npos) << md;
  EXPECT_NE(md.find("| poster | 2.00 / 0.200 (2 / 2) | 2.00 / 0.200 (1 / 2) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| shapes | 4.00 / 0.400 (1 / 1) | – (0 / 1) |"), std::string::npos) << md;
  // Rotation only: no MPE, the ATE instead (and no part of the average).
  EXPECT_NE(md.find("| rotation | ATE 0.250 m, 3.50° (1 / 1) | ATE 0.050 m, 0.50° (1 / 1) |"), std::string::npos)
      << md;
  // eklt: mean of 2 and 4; klt: only poster has a successful run.
  EXPECT_NE(md.find("| **average** | **3.00 / 0.300** (2 scenarios) | **2.00 / 0.200** (1 scenarios) |"),
            std::string::npos)
      << md;
  EXPECT_NE(reportMarkdown(r, "T", {}, {}).find("## Comparison"), std::string::npos);
  // One method, or a sweep: no comparison table.
  const CampaignReport one = aggregateSummary(parseCsv(
      "job_id,scenario,method,sweep,seed,done,status,cause,paper.mpe_percent\na,s,m,n_e=1,1,1,ok,,1\n"));
  EXPECT_EQ(comparisonMarkdown(one), "");
}


TEST(CampaignReport, SweepValuesAreInNumericOrder) {
  // Text order would put 10000 before 2000, 0.01 before 0.0005 and 5e-4 last.
  std::string summary = "job_id,scenario,method,sweep,seed,done,status\n";
  for (const char* v : {"n_e=10000", "n_e=500", "n_e=2000", "n_e=0500.5", "n_e=1000", "r=0.01", "r=5e-4",
                        "r=0.001", "r=off"})
    summary += std::string("j") + v + ",poster,eklt," + v + ",1,0,\n";
  const CampaignReport r = aggregateSummary(parseCsv(summary));
  ASSERT_EQ(r.groups.size(), 9u);
  const std::vector<std::string> expected = {"n_e=500", "n_e=0500.5", "n_e=1000", "n_e=2000", "n_e=10000",
                                             "r=5e-4",  "r=0.001",    "r=0.01",   "r=off"};
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(r.groups[i].sweep, expected[i]) << i;
}

}  // namespace
}  // namespace evio::experiments

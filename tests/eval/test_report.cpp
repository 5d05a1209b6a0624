// Text report, JSON and the ablation table layout.
#include "eval/report.hpp"
#include "eval/trajectory_io.hpp"
#include "fixtures.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace adit::eval {
namespace {

EvalResult offsetResult() {
  const Trajectory gt = test::windingPath(2500);  // ~1.3 km: drift available
  const Trajectory est = test::transformed(gt, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.3, 0.4, 0));
  EvalConfig none;
  none.align = AlignMode::kNone;
  return evaluate(gt, est, none);
}

TEST(Report, TextHasEverySection) {
  const EvalResult r = offsetResult();
  ASSERT_TRUE(r.valid);
  ASSERT_TRUE(r.drift.available);
  const std::string text = formatReport(r);
  for (const char* needle : {"2500 matched", "APE (translation, m)", "rmse 0.5000", "RPE", "1 m trans", "10 m rot",
                             "100 m trans", "KITTI drift", "translation 0.0000 %", "End-point error: 0.5000 m",
                             "distance travelled"})
    EXPECT_NE(text.find(needle), std::string::npos) << needle << "\n" << text;

  EvalResult invalid;
  invalid.message = "no matching timestamps";
  EXPECT_NE(formatReport(invalid).find("not evaluated: no matching timestamps"), std::string::npos);
}

TEST(Report, JsonIsValidAndCarriesTheNumbers) {
  const EvalResult r = offsetResult();
  const std::string json = toJson(r);
  EXPECT_NE(json.find("\"ape_translation_m\": {\"count\": 2500, \"max\": 0.5,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"delta_m\": 100"), std::string::npos);
  EXPECT_NE(json.find("\"available\": true"), std::string::npos);
  EXPECT_EQ(json, toJson(r));  // deterministic

  // Validate with Python's json parser (python3 is part of the project's setup).
  const std::string path = test::tempPath("r.json");
  writeTextFile(path, json);
  const std::string cmd = "/usr/bin/python3 -c \"import json,sys; d=json.load(open('" + path +
                          "')); sys.exit(0 if abs(d['ape_translation_m']['rmse']-0.5)<1e-9 and "
                          "len(d['rpe'])==3 else 1)\"";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  std::remove(path.c_str());
}

TEST(ApeTable, PaperLayoutWithOptionalTimingColumn) {
  ErrorStats a;
  a.max = 1.23456;
  a.min = 0.01;
  a.mean = 0.5;
  a.rmse = 0.6;
  a.std = 0.2;
  ErrorStats b = a;
  b.rmse = 0.25;
  const std::string plain = formatApeTable({{"A-LOAM", a, std::nullopt}, {"+ LinK3D", b, std::nullopt}}, "Table 1");
  std::istringstream lines(plain);
  std::string title, header, rule, row1, row2;
  std::getline(lines, title);
  std::getline(lines, header);
  std::getline(lines, rule);
  std::getline(lines, row1);
  std::getline(lines, row2);
  EXPECT_EQ(title, "Table 1");
  EXPECT_EQ(header, "variant  |      max |      min |     mean |     rmse |      std");
  EXPECT_EQ(row1, "A-LOAM   |    1.235 |    0.010 |    0.500 |    0.600 |    0.200");
  EXPECT_EQ(row2.substr(0, 9), "+ LinK3D ");
  EXPECT_NE(row2.find("0.250"), std::string::npos);
  EXPECT_EQ(rule.size(), header.size());
  EXPECT_EQ(plain.find("ms/sweep"), std::string::npos);

  const std::string timed = formatApeTable({{"A-LOAM", a, 12.345}, {"+ LinK3D", b, std::nullopt}});
  EXPECT_NE(timed.find("ms/sweep"), std::string::npos);
  EXPECT_NE(timed.find("|       12.35"), std::string::npos) << timed;
  EXPECT_NE(timed.find("|           -"), std::string::npos) << timed;
}

}  // namespace
}  // namespace adit::eval
